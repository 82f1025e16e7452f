#include "mapping/reconstruction/reconstruction.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <set>

#include "scanner/common/error.hpp"
#include "scanner/lasers/scan_pattern.hpp"
#include "scanner/sim/trajectory.hpp"
#include "scanner/triangulation/triangulator_factory.hpp"

namespace uwscan::mapping {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// The vehicle path the navigation reports, as an interpolating trajectory.
std::optional<scanner::sim::Trajectory> NavigationTrajectory(const DiveLogReader& log) {
  const std::vector<NavigationRecord> records = log.ReadNavigation();
  if (records.empty()) return std::nullopt;
  scanner::sim::Trajectory trajectory;
  trajectory.T_V_C = log.vehicle_mount().value_or(Eigen::Isometry3d::Identity());
  for (const NavigationRecord& r : records) {
    // Equal timestamps cannot be interpolated between: keep the first.
    if (!trajectory.poses.empty() && !(r.time_s > trajectory.poses.back().time_s)) continue;
    trajectory.poses.push_back({r.time_s, r.T_W_V});
  }
  trajectory.Check();
  return trajectory;
}

}  // namespace

std::unique_ptr<scanner::Triangulator> MakeLogTriangulator(const DiveLogReader& log,
                                                           const ReconstructionOptions& options) {
  const DiveLogHeader& header = log.header();
  const scanner::ScanPattern& pattern = header.scan_pattern;
  scanner::TriangulatorBuildOptions build;
  build.table_cache = options.table_cache;
  if (options.calibration && pattern.kind == scanner::ScannerKind::kMems) {
    build.driven_with = header.scanner.mems().functions;
  }
  try {
    return scanner::MakeTriangulator(
        options.calibration.value_or(header.scanner), pattern,
        options.method.value_or(scanner::DefaultTriangulationMethod(pattern.kind)), build);
  } catch (const Error& e) {
    throw Error(log.path().string() + (options.calibration ? " with the calibration given" : "") +
                ": " + e.what());
  }
}

Reconstruction Reconstruct(const DiveLogReader& log, const ReconstructionOptions& options,
                           const std::function<void(double)>& progress) {
  const DiveLogHeader& header = log.header();
  const scanner::ScanPattern& pattern = header.scan_pattern;
  Reconstruction result;
  result.method = options.method.value_or(scanner::DefaultTriangulationMethod(pattern.kind));

  const Clock::time_point tables_start = Clock::now();
  const std::unique_ptr<scanner::Triangulator> triangulator = MakeLogTriangulator(log, options);
  result.table_seconds = Seconds(tables_start);

  const std::optional<scanner::sim::Trajectory> navigation =
      options.use_navigation ? NavigationTrajectory(log) : std::nullopt;
  result.world_frame = navigation.has_value();

  const std::int64_t frame_count = log.frame_count();
  std::vector<scanner::TriangulatedPoint> triangulated;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::set<int> sweeps;
  double first_time_s = 0.0, last_time_s = 0.0;
  std::int64_t visited = 0;
  log.ForEachFrame(
      [&](const FrameRecord& frame, const GroundTruthRecord* truth) {
        sweeps.insert(frame.sweep);
        ++visited;
        if (progress && frame_count > 0) progress(static_cast<double>(visited) / frame_count);
        if (options.sweep && frame.sweep != *options.sweep) return;
        if (result.frames == 0) first_time_s = frame.time_s;
        last_time_s = frame.time_s;
        triangulated.resize(frame.peaks_px.size());
        const Clock::time_point start = Clock::now();
        triangulator->TriangulateFrame(frame.command, frame.peaks_px, triangulated);
        result.triangulation_seconds += Seconds(start);

        const Eigen::Isometry3d T_out_C =
            navigation ? navigation->T_W_C(frame.time_s) : Eigen::Isometry3d::Identity();
        // Truth is stored in the world frame: bring it to the output frame.
        const Eigen::Isometry3d T_out_W =
            navigation || truth == nullptr ? Eigen::Isometry3d::Identity() : truth->T_W_C.inverse();
        for (size_t i = 0; i < triangulated.size(); ++i) {
          if (!triangulated[i].ok()) continue;
          result.points.push_back(T_out_C * triangulated[i].p_C);
          result.frame_of_point.push_back(frame.index);
          if (truth != nullptr) {
            const bool has_truth = i < truth->points_W.size() && truth->points_W[i].allFinite();
            result.truth.push_back(has_truth ? Eigen::Vector3d(T_out_W * truth->points_W[i])
                                             : Eigen::Vector3d::Constant(nan));
          }
        }
        result.peaks += static_cast<std::int64_t>(frame.peaks_px.size());
        ++result.frames;
      },
      /*with_truth=*/true);
  result.sweeps.assign(sweeps.begin(), sweeps.end());
  if (options.relative_to_middle && navigation && result.frames > 0) {
    const Eigen::Isometry3d T_C_W = navigation->T_W_C(0.5 * (first_time_s + last_time_s)).inverse();
    for (Eigen::Vector3d& p : result.points) p = T_C_W * p;
    for (Eigen::Vector3d& p : result.truth) p = T_C_W * p;  // NaN stays NaN
    result.world_frame = false;
  }
  // A log without ground truth has none for any point; one with it has it for every point.
  if (result.truth.size() != result.points.size()) result.truth.clear();
  return result;
}

std::optional<TruthError> CompareToTruth(const Reconstruction& reconstruction) {
  TruthError error;
  double sum = 0.0, sum2 = 0.0;
  for (size_t i = 0; i < reconstruction.truth.size(); ++i) {
    if (!reconstruction.truth[i].allFinite()) continue;
    const double d = (reconstruction.points[i] - reconstruction.truth[i]).norm();
    sum += d;
    sum2 += d * d;
    error.max_m = std::max(error.max_m, d);
    ++error.points;
  }
  if (error.points == 0) return std::nullopt;
  const double n = static_cast<double>(error.points);
  error.mean_m = sum / n;
  error.rms_m = std::sqrt(sum2 / n);
  error.std_m = std::sqrt(std::max(0.0, sum2 / n - error.mean_m * error.mean_m));
  return error;
}

}  // namespace uwscan::mapping
