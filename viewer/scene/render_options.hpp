#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <optional>
#include <string>

#include "viewer/scene/colour_map.hpp"

namespace uwscan::viewer {

// What a point's colour shows.
enum class ColourMode {
  kHeight,     // position along RenderOptions::up, metres
  kError,      // distance to the true surface point, metres (dive logs with ground truth)
  kIntensity,  // the cloud's intensity values
  kObject,     // one colour per file, or per scene object when the points know theirs
  // Signed deviation from a reference, metres (a change report): a diverging map about zero,
  // grey where the deviation is not significant.
  kDeviation,
};
enum class CameraPreset {
  kFit,   // oblique, from above, the whole scene in view
  kTop,   // looking down along -up
  kSide,  // looking horizontally
};

// Parse "height|error|intensity|object|deviation" and "fit|top|side"; std::nullopt otherwise.
std::optional<ColourMode> ParseColourMode(const std::string& text);
std::optional<CameraPreset> ParseCameraPreset(const std::string& text);
const char* ToString(ColourMode mode);

struct RenderOptions {
  ColourMode colour = ColourMode::kHeight;
  // Fixed scalar range of the colour map (metres for height and error); std::nullopt: the 1st
  // to 99th percentile of the values shown (RobustRange).
  std::optional<ScalarRange> range;
  double point_size_px = 2.0;      // > 0
  bool eye_dome_lighting = false;  // vtkEDLShading: shapes of colourless scans read as relief
  CameraPreset camera = CameraPreset::kFit;
  int width_px = 1280;  // window or picture size, [16, 8192]
  int height_px = 960;
  // At most this many points are handed to VTK; above it every k-th point of every cloud is
  // drawn (the same points every time), so big clouds stay interactive. >= 1.
  std::size_t max_points = 2'000'000;
  // The world's "up" (unit after normalisation): NED, so -z by default (DESIGN.md).
  Eigen::Vector3d up = Eigen::Vector3d(0.0, 0.0, -1.0);
  bool colour_bar = true;  // the scalar bar of continuous colour modes
  Rgb background{24, 28, 36};

  // Throws uwscan::Error naming the field when a value is out of range.
  void Check() const;
};

}  // namespace uwscan::viewer
