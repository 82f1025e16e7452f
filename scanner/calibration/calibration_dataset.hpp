#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "scanner/calibration/observations.hpp"
#include "scanner/lasers/scanner.hpp"

namespace uwscan::scanner::calibration {

// A calibration dataset: one folder of camera images (PNG, 8- or 16-bit greyscale) and
// `manifest.yaml` saying which calibration step they are for and what each image shows
// (format in data/README.md, "Calibration datasets"). Real datasets are recorded by hand; the
// simulator writes them with their truth (dataset_simulation.hpp).
//
// The steps, in the order a scanner is calibrated (seed 000; seed 001 does 1, 2 and 5):
//   intrinsics      `views`: the pattern in air, the camera's pinhole and distortion
//   viewport        `views`: the pattern under water, the camera viewport
//   laser           `planes` with galvanometer `stripes`, in air: laser and mirror
//   laser_viewport  `planes` with `stripes`, under water: the laser viewport
//   mems            `planes` with MEMS laser `dots`, under water: projection functions f1..f6

inline constexpr const char* kManifestFileName = "manifest.yaml";

// The step names above, in that order.
const std::vector<std::string>& CalibrationSteps();

struct CalibrationDataset {
  std::filesystem::path folder;
  std::string step;  // one of CalibrationSteps()
  PatternSpec pattern;
  // The scanner as known before this step (CAD values, results of earlier steps), resolved
  // against `folder`; absent when the step starts from nothing (intrinsics).
  std::optional<std::filesystem::path> scanner_file;
  int width_px = 0;  // every image's size, pixels
  int height_px = 0;
  // intrinsics, viewport: one pattern image each (file names relative to `folder`).
  std::vector<std::string> views;
  // laser, laser_viewport, mems: the board held at one pose each.
  struct Plane {
    std::string pattern_image;  // laser off, board lit: fixes the plane's pose
    std::vector<std::pair<std::string, int>> stripes;           // image, mirror step
    std::vector<std::pair<std::string, Eigen::Vector2d>> dots;  // image, volts (x, y)
  };
  std::vector<Plane> planes;
  // Simulated datasets: the truth behind the images (DatasetTruth), resolved against `folder`.
  std::optional<std::filesystem::path> truth_file;
  // Refractive index of the medium in front of the viewports when the images were taken (1.0:
  // in air); std::nullopt: the scanner file's own n_water applies.
  std::optional<double> water_refractive_index;

  std::filesystem::path ImagePath(const std::string& image) const { return folder / image; }
};

// Reads and validates `folder`/manifest.yaml. Throws uwscan::Error naming the file (and
// file:line and the field, for what the manifest says) on: a missing folder or manifest,
// malformed YAML, an unknown or misspelt field, an unknown step, a missing, unreadable or
// non-greyscale image or one whose size is not image_size, an image named twice, a step
// without the data it needs (intrinsics and viewport: >= 3 views; laser steps: >= 2 planes,
// each with stripes, >= 2 distinct mirror steps in all; mems: >= 2 planes, each with dots) or
// with data of another step, a mirror step or voltage pair repeated on one plane, volts that
// are not finite, a missing scanner or truth file.
CalibrationDataset LoadCalibrationDataset(const std::filesystem::path& folder);

// Writes dataset.folder/manifest.yaml, after the checks LoadCalibrationDataset makes (so every
// image must be in place first). Written to a temporary file in the folder and renamed over
// the manifest, so a reader sees the old manifest or the new one, never half of one. Paths to
// the scanner and truth files are written relative to the folder when they lie inside it.
void WriteCalibrationManifest(const CalibrationDataset& dataset);

// What a simulated dataset was made from: the true scanner (the simulator's effective scanner:
// water index, refraction and distortion as simulated) and the true board poses, one per
// view or plane, in the order of the manifest.
struct DatasetTruth {
  Scanner scanner;
  std::vector<Eigen::Isometry3d> T_C_O_views;
  std::vector<Eigen::Isometry3d> T_C_O_planes;
};

// truth.yaml: {uwscan_format: 1, dataset: calibration_truth, scanner: |- <scanner file text>,
// T_C_O_views: [poses], T_C_O_planes: [poses]}; poses as in scanner files, written with
// round-trip precision. Both throw uwscan::Error naming the file (and line, field).
DatasetTruth LoadDatasetTruth(const std::filesystem::path& path);
void WriteDatasetTruth(const std::filesystem::path& path, const DatasetTruth& truth);

}  // namespace uwscan::scanner::calibration
