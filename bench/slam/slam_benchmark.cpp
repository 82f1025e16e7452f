#include "bench/slam/slam_benchmark.hpp"

#include <omp.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <sstream>

#include "bench/scratch_folder.hpp"
#include "mapping/log/dive_simulation.hpp"
#include "mapping/reconstruction/reconstruction.hpp"
#include "mapping/slam/map_report.hpp"
#include "mapping/slam/submap.hpp"
#include "perception/preprocessing/voxel_filter.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/sim/ray_caster.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"

namespace uwscan::bench {
namespace {

// Map points further than this from every true surface count at this distance (outliers).
constexpr double kSurfaceSearch_m = 0.5;

std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot read");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// The dive's frames triangulated as the mapper does and placed with the true camera pose of each:
// the map no trajectory estimate can beat, voxelised as the maps it is compared with. What
// separates it from the true surfaces is the sensor's own error (peak noise, refraction at
// grazing angles, voxel centroids across edges).
perception::PointCloud TruePoseMap(const mapping::DiveLogReader& log,
                                   const std::filesystem::path& table_cache, double voxel_m) {
  mapping::ReconstructionOptions options;
  options.use_navigation = false;
  options.table_cache = table_cache;
  const mapping::Reconstruction r = mapping::Reconstruct(log, options);
  std::vector<Eigen::Vector3d> points_W;
  points_W.reserve(r.points.size());
  std::int64_t frame = -1;
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    if (r.frame_of_point[i] != frame) {
      frame = r.frame_of_point[i];
      const std::optional<mapping::GroundTruthRecord> truth = log.ReadGroundTruth(frame);
      if (!truth)
        throw Error(log.path().string() + ": frame " + std::to_string(frame) +
                    " has no ground truth");
      T_W_C = truth->T_W_C;
    }
    points_W.push_back(T_W_C * r.points[i]);
  }
  perception::VoxelFilterOptions voxel;
  voxel.leaf_m = voxel_m;
  return perception::VoxelDownsample(perception::MakeCloud(points_W), voxel);
}

// The dive's submaps placed with other poses (the dead reckoning's, a peer's), voxelised.
perception::PointCloud PlacedMap(const mapping::DiveMapping& m,
                                 const std::vector<mapping::TimedPose>& poses, double voxel_m) {
  std::vector<const perception::PointCloud*> clouds;
  std::vector<Eigen::Isometry3d> placed;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    clouds.push_back(&m.submap_clouds[i]);
    placed.push_back(poses[i].T_W_V);
  }
  return mapping::MergeClouds(clouds, placed, voxel_m);
}

// The scene's text with its top-level seed set to `seed` (added when it has none), so that the
// log records the scene it was simulated from.
std::string WithSeed(const std::string& yaml_text, std::uint64_t seed) {
  std::istringstream in(yaml_text);
  std::ostringstream out;
  bool found = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("seed:", 0) == 0) {
      line = "seed: " + std::to_string(seed);
      found = true;
    }
    out << line << '\n';
  }
  if (!found) out << "seed: " << seed << '\n';
  return out.str();
}

// Maps the dive's log and measures it against the truth (the scene's surfaces) and the peers,
// into `f`; the log is closed on return.
void MapAndMeasure(const std::filesystem::path& log_path, const scanner::sim::Scene& scene,
                   const SlamBenchOptions& options, const std::string& label,
                   const Progress& progress, DiveFigures* out) {
  DiveFigures& f = *out;
  mapping::DiveMappingOptions map_options;
  map_options.mapper.threads = options.threads;
  map_options.table_cache = options.table_cache;
  map_options.keep_submaps = true;
  omp_set_num_threads(options.threads);
  const mapping::DiveLogReader log(log_path);
  const mapping::DiveMapping m = mapping::MapDive(log, map_options, [&](double fraction) {
    if (progress) progress("map " + label, fraction);
  });
  if (m.truth.empty()) throw Error(f.name + ": the simulated log has no truth");
  const mapping::MapSummary s = mapping::Summarise(m);
  f.duration_s = m.dive_duration_s;
  f.submaps = m.submaps;
  f.loops_accepted = s.loops_accepted;
  f.loops_rejected = s.loops_rejected;
  f.loops_false = s.loops_false.value_or(0);
  f.loops_missed = s.loops_missed.value_or(0);
  f.registrations_missed = s.registrations_missed.value_or(0);
  f.nees_mean = s.nees_mean;
  f.real_time_factor = s.real_time_factor;
  f.expected_map_error_m = m.expected_map_error_m;
  f.expected_ate_m = m.expected_position_error_m;

  const scanner::sim::RayCaster caster(scene.objects);
  if (progress) progress("surface distances " + label, 0.0);
  f.dead_reckoning.ate_m = *s.ate_dead_reckoning_m;
  f.dead_reckoning.rpe_per_m = s.rpe_dead_reckoning_per_m;
  f.dead_reckoning.map = DistanceToScene(PlacedMap(m, m.dead_reckoning, map_options.map_voxel_m),
                                         caster, options.threads);
  f.slam.ate_m = *s.ate_slam_m;
  f.slam.rpe_per_m = s.rpe_slam_per_m;
  f.slam.map = DistanceToScene(m.map, caster, options.threads);
  f.slam.seconds = m.seconds;
  f.true_poses_map = DistanceToScene(TruePoseMap(log, options.table_cache, map_options.map_voxel_m),
                                     caster, options.threads);
  if (options.run_open3d && Open3dMultiwayAvailable()) {
    if (progress) progress("open3d " + label, 0.0);
    TrajectoryFigures o;
    const std::vector<mapping::TimedPose> poses = Open3dMultiway(m, options.threads, &o.seconds);
    o.ate_m = mapping::AbsoluteTrajectoryError(poses, m.truth);
    o.rpe_per_m = mapping::RelativeErrorPerMetre(poses, m.truth);
    o.map = DistanceToScene(PlacedMap(m, poses, map_options.map_voxel_m), caster, options.threads);
    f.open3d = o;
  }
}

// One dive of a scene with the given seed: simulated into a log in `folder`, mapped, measured;
// the log is removed afterwards (a long dive's is hundreds of MB).
DiveFigures BenchDive(const std::filesystem::path& scene_path, std::uint64_t seed,
                      const SlamBenchOptions& options, const std::filesystem::path& folder,
                      const Progress& progress) {
  DiveFigures f;
  f.name = scene_path.stem().string();
  f.seed = seed;
  const std::string scene_text =
      WithSeed(SceneWithWalkScale(ReadText(scene_path), options.walk_scale, scene_path), f.seed);
  const scanner::sim::Scene scene =
      scanner::sim::ParseScene(scene_text, scene_path.string(), scene_path.parent_path());
  if (scene.seed != f.seed) {
    throw Error(scene_path.string() + ": its seed could not be set to " + std::to_string(f.seed) +
                " (expected one top-level line 'seed: N')");
  }
  const std::string label = f.name + " (seed " + std::to_string(f.seed) + ")";
  const std::filesystem::path log_path = folder / (f.name + "_" + std::to_string(f.seed) + ".db");
  {
    const scanner::sim::Simulator simulator(scene);
    mapping::DiveSimulationOptions sim_options;
    sim_options.threads = options.threads;
    sim_options.producer = "uwscan bench slam";
    const mapping::DiveSimulationSummary summary =
        mapping::SimulateDive(simulator, scene_text, log_path, sim_options, [&](double fraction) {
          if (progress) progress("simulate " + label, fraction);
        });
    f.simulate_seconds = summary.seconds;
  }
  MapAndMeasure(log_path, scene, options, label, progress, &f);
  if (progress) progress("surface distances " + label, 1.0);
  for (const char* suffix : {"", "-wal", "-shm", "-journal"}) {
    std::error_code ignored;  // a leftover the scratch folder removes at the end anyway
    std::filesystem::remove(log_path.string() + suffix, ignored);
  }
  return f;
}

}  // namespace

SurfaceDistance DistanceToScene(const perception::PointCloud& map,
                                const scanner::sim::RayCaster& caster, int threads) {
  std::vector<double> distances(map.size());
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(map.size()); ++i) {
    const std::optional<double> d =
        caster.DistanceToSurface(map.Point(static_cast<size_t>(i)), kSurfaceSearch_m);
    distances[static_cast<size_t>(i)] = d.value_or(kSurfaceSearch_m);
  }
  SurfaceDistance out;
  out.points = distances.size();
  if (distances.empty()) return out;
  double sum = 0.0, sum2 = 0.0;
  for (double d : distances) {
    sum += d;
    sum2 += d * d;
  }
  out.mean_m = sum / static_cast<double>(distances.size());
  out.rms_m = std::sqrt(sum2 / static_cast<double>(distances.size()));
  const std::size_t k = static_cast<std::size_t>(0.95 * static_cast<double>(distances.size() - 1));
  std::nth_element(distances.begin(), distances.begin() + static_cast<std::ptrdiff_t>(k),
                   distances.end());
  out.p95_m = distances[k];
  return out;
}

void SlamBenchOptions::Check() const {
  const OptionChecks check("SlamBenchOptions");
  check.Require(!scenes.empty(), "scenes", "at least one scene", "none");
  check.GreaterThan("seeds", seeds, 0);
  check.GreaterThan("threads", threads, 0);
  check.Positive("walk_scale", walk_scale);
}

std::string SceneWithWalkScale(const std::string& yaml_text, double scale,
                               const std::filesystem::path& scene_path) {
  if (scale == 1.0) return yaml_text;
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw Error(scene_path.string() + ": not YAML (" + e.what() + ")");
  }
  YAML::Node drift = root["effects"] ? root["effects"]["navigation_drift"] : YAML::Node();
  if (!drift || !drift.IsMap()) {
    throw Error(scene_path.string() + ": a walk scale needs the scene's effects.navigation_drift");
  }
  for (const char* key : {"position_walk_m_per_sqrt_s", "yaw_walk_rad_per_sqrt_s"}) {
    if (drift[key]) drift[key] = drift[key].as<double>() * scale;
  }
  YAML::Emitter out;
  out << root;
  return std::string(out.c_str()) + "\n";
}

std::vector<DiveFigures> RunSlamBench(const SlamBenchOptions& options, const Progress& progress) {
  options.Check();
  ScratchFolder scratch("bench-slam");
  std::vector<DiveFigures> dives;
  for (const std::filesystem::path& scene_path : options.scenes) {
    const std::uint64_t first_seed = scanner::sim::LoadScene(scene_path).seed;
    for (int draw = 0; draw < options.seeds; ++draw) {
      dives.push_back(BenchDive(scene_path, first_seed + static_cast<std::uint64_t>(draw), options,
                                scratch.path(), progress));
    }
  }
  return dives;
}

}  // namespace uwscan::bench
