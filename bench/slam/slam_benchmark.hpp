#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bench/progress.hpp"
#include "mapping/slam/dive_mapping.hpp"

namespace uwscan::scanner::sim {
class RayCaster;
}

namespace uwscan::bench {

// Scan-matching SLAM against dead reckoning and against Open3D's multiway registration on the
// same submaps, on simulated inspection dives, in one run.
struct SlamBenchOptions {
  std::vector<std::filesystem::path> scenes;  // dive scenes (data/scenes/inspection_*.yaml)
  // Each scene is dived this many times, with its own seed and the next ones: one seed's drift
  // draw is luck, good or bad, as much as it is the mapper.
  int seeds = 1;
  int threads = 2;
  // The scenes' navigation random walks (position and heading) multiplied by this, > 0: what
  // SLAM's error owes to the walk (within each sweep and between the places the scans pin),
  // against the DVL's scale error and misalignment, which this leaves as they are.
  double walk_scale = 1.0;
  bool run_open3d = true;
  std::filesystem::path table_cache;
  void Check() const;
};

// Distance of a map's points to the scene's true surfaces.
struct SurfaceDistance {
  double mean_m = 0.0;
  double rms_m = 0.0;
  double p95_m = 0.0;
  std::size_t points = 0;
};

// The distance of each map point to the nearest true surface the caster holds (points further
// than 0.5 m count at 0.5 m, as outliers), summarised.
SurfaceDistance DistanceToScene(const perception::PointCloud& map,
                                const scanner::sim::RayCaster& caster, int threads);

struct TrajectoryFigures {
  double ate_m = 0.0;
  std::optional<double> rpe_per_m;
  SurfaceDistance map;
  double seconds = 0.0;
};

struct DiveFigures {
  std::string name;
  std::uint64_t seed = 0;  // the scene's, which draws the navigation's drift and the peaks' noise
  double duration_s = 0.0;
  int submaps = 0;
  TrajectoryFigures dead_reckoning, slam;
  std::optional<TrajectoryFigures> open3d;
  // The same frames placed with the true poses: the map's floor, the sensor's own error.
  SurfaceDistance true_poses_map;
  int loops_accepted = 0, loops_rejected = 0, loops_false = 0;
  int loops_missed = 0;  // right loops the chi-square turned away (MapSummary::loops_missed)
  // Right consecutive registrations it turned away (MapSummary::registrations_missed).
  int registrations_missed = 0;
  std::optional<double> nees_mean;
  // What the SLAM map's distance to the true surfaces should be from its poses' uncertainty
  // alone (mapping::ExpectedSurfaceErrorRms): with a consistent covariance, what the
  // navigation and the scene allow.
  std::optional<double> expected_map_error_m;
  // The SLAM trajectory's RMS position error as its covariance predicts it (what the ATE should
  // come to: ExpectedPositionErrorRms).
  std::optional<double> expected_ate_m;
  double real_time_factor = 0.0;
  double simulate_seconds = 0.0;
};

std::vector<DiveFigures> RunSlamBench(const SlamBenchOptions& options,
                                      const Progress& progress = {});

// A scene's YAML text with its navigation's random walks (position and heading) multiplied by
// `scale` (SlamBenchOptions::walk_scale), everything else as it was; the text itself when the
// scale is 1. Throws naming `scene_path` when the text is not YAML or the scene has no navigation
// drift to scale.
std::string SceneWithWalkScale(const std::string& yaml_text, double scale,
                               const std::filesystem::path& scene_path);

// Open3D's multiway registration (pairwise point-to-plane ICP of each submap with the three
// before it and with the nearest older one its navigated position overlaps, about the pairs
// uwscan's mapper tries; then GlobalOptimization with its line process) on the submaps of
// `mapping`, started from the dead reckoning: the submap poses it finds. Throws when Open3D is not
// built in.
std::vector<mapping::TimedPose> Open3dMultiway(const mapping::DiveMapping& mapping, int threads,
                                               double* seconds);
bool Open3dMultiwayAvailable();

}  // namespace uwscan::bench
