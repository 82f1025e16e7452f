#include "viewer/scene/render_options.hpp"

#include <cmath>

#include "scanner/common/option_checks.hpp"

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
  const OptionChecks check("RenderOptions");
  if (range) {
    check.Require(std::isfinite(range->lo) && std::isfinite(range->hi) && range->hi > range->lo,
                  "range", "two finite numbers, low < high", OptionPairText(range->lo, range->hi));
  }
  check.InRange("point_size_px", point_size_px, 0.0, 64.0, Interval::kOpenLow, "px");
  check.InRange("width_px", width_px, 16, 8192, Interval::kClosed, "px");
  check.InRange("height_px", height_px, 16, 8192, Interval::kClosed, "px");
  check.AtLeast("max_points", max_points, 1);
  check.Require(up.allFinite() && up.norm() > 1e-9, "up", "a finite, non-zero vector");
}

}  // namespace uwscan::viewer
