#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "scanner/calibration/observations.hpp"
#include "scanner/calibration/target_renderer.hpp"
#include "scanner/sim/scene.hpp"

namespace uwscan::scanner::calibration {

// A calibration scene: what the simulator needs to write a calibration dataset for one step
// (format in data/README.md, "Calibration scenes"). It is a scene file (water, scanner, effects,
// detector, seed) with a top-level `calibration:` section instead of objects and trajectory: the
// camera stays at the world origin and the board, the only object, takes random poses in front
// of it. The scene's scanner file is the truth the images are made from.
struct CalibrationScene {
  sim::Scene scene;  // as a scene file reads, with no objects; scene.source names the file
  std::string step;  // one of CalibrationSteps()
  PatternSpec pattern;
  Eigen::Vector2d board_size_m = Eigen::Vector2d::Zero();  // 0: pattern + one square margin
  double board_reflectance = 0.8;  // diffuse albedo of the white paper, for the laser, (0, 1]

  // What the dataset's manifest gives as the scanner known before the step: a copy of this
  // file (CAD values), with the sections named in initial_true_sections (top-level keys such as
  // camera, camera_viewport, laser) taken from the true scanner instead, as earlier steps of a
  // calibration would have delivered them. Absent: the manifest names no scanner.
  std::optional<std::filesystem::path> initial_scanner;
  std::vector<std::string> initial_true_sections;

  int views = 20;                        // intrinsics, viewport: board poses (one image each)
  int planes = 6;                        // laser steps, mems: board poses
  Eigen::Vector2d distance_m{0.5, 1.2};  // depth of the board's centre in {C}, metres
  double max_tilt_rad = 0.6;         // board normal away from the camera ray to its centre, radians
  double max_roll_rad = 0.3;         // board turned about its normal, radians
  std::vector<int> mirror_steps;     // laser steps: galvanometer steps imaged per plane
  Eigen::Vector2i volts_grid{9, 9};  // mems: voltage pairs across x and y
  double volts_fraction = 0.9;       // mems: grid spread over this part of +-max_volts
  // Shrinks the camera (pixel grid and intrinsics together, the field of view unchanged) for
  // quick datasets; the truth and the initial scanner get the shrunk camera too. (0, 1].
  double image_scale = 1.0;
  // Pattern images (lights on, laser off), in the dataset's format, effects.image.format (the
  // scene file gives levels and noise in 8-bit units; the reader scales them by 257 for mono16).
  TargetRenderOptions render;

  // Throws uwscan::Error naming the field (calibration.views, ...) when a value is unusable or
  // does not fit the step or the scanner; the reader's checks, for scenes built or changed in
  // code.
  void Check() const;
};

// Reads a calibration scene. Relative paths (scanner file, initial scanner) are resolved
// against base_dir. Throws uwscan::Error naming source:line and the field: everything the scene
// reader checks, plus an unknown step, a field the step does not use, a step the scanner cannot
// do (stripes need a galvanometer scanner, mems a MEMS one), mirror steps outside the laser's
// range, and objects or a trajectory (the board is posed by the simulation).
CalibrationScene ParseCalibrationScene(const std::string& yaml_text, const std::string& source,
                                       const std::filesystem::path& base_dir);
CalibrationScene LoadCalibrationScene(const std::filesystem::path& path);

}  // namespace uwscan::scanner::calibration
