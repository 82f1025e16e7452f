#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mapping/log/dive_log.hpp"
#include "scanner/lasers/scanner.hpp"
#include "scanner/triangulation/triangulator.hpp"

namespace uwscan::mapping {

struct ReconstructionOptions {
  // std::nullopt: the scanner's default (ray-cone for the galvanometer, ray-plane for MEMS).
  std::optional<scanner::TriangulationMethod> method;
  // Put points in the world frame using the log's navigation when it has some; otherwise (or
  // when false) every point stays in the camera frame {C} of the scanner.
  bool use_navigation = true;
  // A calibration to triangulate with instead of the scanner the log was recorded with;
  // std::nullopt: the log's own.
  std::optional<scanner::Scanner> calibration;
  // Folder keeping per-calibration tables between runs; empty: computed every time.
  std::filesystem::path table_cache;
  // Only the frames of this sweep; std::nullopt: every frame.
  std::optional<int> sweep;
  // With use_navigation and navigation in the log: each frame still placed with the navigation
  // at its own time, but the points given in the camera frame at the middle of the frames
  // reconstructed instead of the world frame: a sweep taken while the vehicle moved, as a
  // sensor at rest at that moment would have seen it.
  bool relative_to_middle = false;
};

// A dive's point cloud, point by point with the frame it came from, and the truth of each point
// when the log is simulated (in the same frame as the points; NaN where a peak had none).
struct Reconstruction {
  scanner::TriangulationMethod method = scanner::TriangulationMethod::kRayCone;
  bool world_frame = false;
  std::vector<Eigen::Vector3d> points;
  std::vector<std::int64_t> frame_of_point;
  std::vector<Eigen::Vector3d> truth;  // empty when the log holds no ground truth
  std::int64_t frames = 0;             // reconstructed (of the sweep chosen, if one is)
  std::vector<int> sweeps;             // every sweep of the log, ascending, chosen or not
  std::int64_t peaks = 0;              // peaks read; peaks - points.size() had no point
  double table_seconds = 0.0;          // building the per-calibration tables, once
  double triangulation_seconds = 0.0;  // the triangulation itself, all frames
};

// Distance of each reconstructed point from its truth (points without truth are skipped).
struct TruthError {
  std::int64_t points = 0;
  double mean_m = 0.0;
  double std_m = 0.0;
  double rms_m = 0.0;
  double max_m = 0.0;
};
// std::nullopt when the reconstruction has no truth for any point.
std::optional<TruthError> CompareToTruth(const Reconstruction& reconstruction);

// The triangulator of a log's frames: with the log's own scanner, or with options.calibration
// (for a MEMS scanner, on the lines the log's own scanner designed and drove: a calibration
// changes where their voltages send the beam, not the voltages). Throws uwscan::Error naming
// the log.
std::unique_ptr<scanner::Triangulator> MakeLogTriangulator(const DiveLogReader& log,
                                                           const ReconstructionOptions& options);

// Triangulates every frame of a dive log with the scanner configuration and scan pattern it
// stores (tables built once), then places each point with the navigation interpolated at its
// frame's time. `progress` (optional) receives the fraction done.
Reconstruction Reconstruct(const DiveLogReader& log, const ReconstructionOptions& options,
                           const std::function<void(double)>& progress = {});

}  // namespace uwscan::mapping
