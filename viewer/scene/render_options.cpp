#include "viewer/scene/render_options.hpp"

#include <cmath>

#include "scanner/common/error.hpp"

namespace uwscan::viewer {

std::optional<ColourMode> ParseColourMode(const std::string& text) {
  if (text == "height") return ColourMode::kHeight;
  if (text == "error") return ColourMode::kError;
  if (text == "intensity") return ColourMode::kIntensity;
  if (text == "object") return ColourMode::kObject;
  if (text == "deviation") return ColourMode::kDeviation;
  return std::nullopt;
}

std::optional<CameraPreset> ParseCameraPreset(const std::string& text) {
  if (text == "fit") return CameraPreset::kFit;
  if (text == "top") return CameraPreset::kTop;
  if (text == "side") return CameraPreset::kSide;
  return std::nullopt;
}

const char* ToString(ColourMode mode) {
  switch (mode) {
    case ColourMode::kHeight:
      return "height";
    case ColourMode::kError:
      return "error";
    case ColourMode::kIntensity:
      return "intensity";
    case ColourMode::kObject:
      return "object";
    case ColourMode::kDeviation:
      return "deviation";
  }
  return "?";
}

void RenderOptions::Check() const {
  if (range && !(std::isfinite(range->lo) && std::isfinite(range->hi) && range->hi > range->lo)) {
    throw Error("render options: range must be two finite numbers, low < high");
  }
  if (!(point_size_px > 0.0 && point_size_px <= 64.0)) {
    throw Error("render options: point_size_px must be in (0, 64]");
  }
  if (width_px < 16 || width_px > 8192 || height_px < 16 || height_px > 8192) {
    throw Error("render options: width and height must be in [16, 8192] pixels");
  }
  if (max_points < 1) throw Error("render options: max_points must be >= 1");
  if (!(up.allFinite() && up.norm() > 1e-9)) {
    throw Error("render options: up must be a finite, non-zero vector");
  }
}

}  // namespace uwscan::viewer
