#include "apps/mapping/map_command.hpp"

#include <omp.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "apps/cli/data_cache.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/malloc_arena.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/output_path.hpp"
#include "apps/cli/progress_bar.hpp"
#include "mapping/slam/dive_mapping.hpp"
#include "mapping/slam/map_report.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/temporary_folder.hpp"

namespace uwscan::app {
namespace {

struct MapArgs {
  std::string log;
  std::string output;
  std::string trajectory;
  std::string dead_reckoning;
  std::string truth;
  std::string json;
  double voxel_m = 0.005;
  int sweeps_per_submap = mapping::MapperOptions{}.sweeps_per_submap;
  double max_navigation_gap_s = mapping::MapperOptions{}.max_navigation_gap_s;
  bool whole_graph_solves = false;
  double whole_solve_lag_s = mapping::MapperOptions{}.whole_solve_lag_s;
  int threads = 0;
};

nlohmann::json TumRows(const std::vector<mapping::TimedPose>& poses) {
  nlohmann::json rows = nlohmann::json::array();
  for (const mapping::TimedPose& p : poses) {
    const Eigen::Quaterniond q(p.T_W_V.linear());
    const Eigen::Vector3d& t = p.T_W_V.translation();
    rows.push_back({p.time_s, t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()});
  }
  return rows;
}

template <typename T>
nlohmann::json Optional(const std::optional<T>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
}

// The pose graph's information, from which `compare` takes how well two poses are placed
// relative to each other: its upper triangle as [row, column, value], 6 rows per graph node
// [rotation (rad), position (m)], each SLAM pose at its `pose_columns` entry.
nlohmann::json InformationJson(const mapping::JointPoseUncertainty& uncertainty) {
  const Eigen::SparseMatrix<double>& information = uncertainty.information();
  nlohmann::json entries = nlohmann::json::array();
  for (Eigen::Index column = 0; column < information.outerSize(); ++column) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(information, column); it; ++it)
      if (it.row() <= it.col()) entries.push_back({it.row(), it.col(), it.value()});
  }
  return {{"size", information.rows()},
          {"pose_columns", uncertainty.pose_columns()},
          {"upper_entries", entries}};
}

// The map report (format in docs/formats.md, "Map report"): what the viewer reads.
nlohmann::json MapReportJson(const mapping::DiveMapping& m, const std::string& log,
                             const std::string& map) {
  const mapping::MapSummary s = mapping::Summarise(m);
  // Both absolute: the report may be read from anywhere.
  const auto absolute = [](const std::string& path) {
    return std::filesystem::absolute(path).lexically_normal().string();
  };
  nlohmann::json report = {{"uwscan_format", 1}, {"kind", "map_report"}, {"log", absolute(log)}};
  report["map"] = absolute(map);
  report["trajectories"] = {{"slam", TumRows(m.slam)},
                            {"dead_reckoning", TumRows(m.dead_reckoning)}};
  if (!m.truth.empty()) report["trajectories"]["truth"] = TumRows(m.truth);
  nlohmann::json covariance = nlohmann::json::array(), deviation = nlohmann::json::array();
  for (std::size_t i = 0; i < m.covariances.size(); ++i) {
    // Reordered to (x, y, z, roll, pitch, yaw): position first, as the report documents.
    const Eigen::Matrix<double, 6, 6>& c = m.covariances[i];
    Eigen::Matrix<double, 6, 6> ordered;
    ordered << c.bottomRightCorner<3, 3>(), c.bottomLeftCorner<3, 3>(), c.topRightCorner<3, 3>(),
        c.topLeftCorner<3, 3>();
    nlohmann::json row = {m.slam[i].time_s};
    for (int r = 0; r < 6; ++r) {
      for (int k = 0; k < 6; ++k) row.push_back(ordered(r, k));
    }
    covariance.push_back(row);
    const Eigen::Matrix<double, 6, 1> std = mapping::PoseStd(m.covariances[i]);
    deviation.push_back({m.slam[i].time_s, std(0), std(1), std(2), std(3), std(4), std(5)});
  }
  report["pose_covariance"] =
      covariance;  // [t, 36 values, (x, y, z (m), roll, pitch, yaw (rad)) row-major]
  report["pose_std"] = deviation;  // [t, x, y, z (m), roll, pitch, yaw (rad)]
  if (m.joint_uncertainty) report["pose_graph_information"] = InformationJson(*m.joint_uncertainty);
  nlohmann::json loops = nlohmann::json::array();
  for (const mapping::LoopClosure& l : m.loops) {
    const Eigen::Quaterniond q(l.T_from_to.linear());
    const Eigen::Vector3d& t = l.T_from_to.translation();
    loops.push_back({{"from_submap", l.from},
                     {"to_submap", l.to},
                     {"accepted", l.accepted},
                     {"reason", l.reason},
                     {"fitness", l.fitness},
                     {"chi2", l.chi2},
                     {"constrained_directions", l.constrained_directions},
                     {"prediction_std_m", l.prediction_std_m},
                     {"T_from_to", {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()}}});
  }
  report["loops"] = loops;
  report["figures"] = {{"submaps", m.submaps},
                       {"frames_mapped", m.stats.frames},
                       {"frames_without_navigation", m.stats.frames_without_navigation},
                       {"map_points", m.map.size()},
                       {"dive_duration_s", m.dive_duration_s},
                       {"seconds", m.seconds},
                       {"real_time_factor", s.real_time_factor},
                       {"registrations", m.stats.registrations},
                       {"registrations_left_to_navigation",
                        m.stats.registrations_failed + m.stats.registrations_inconsistent},
                       {"registrations_inconsistent", m.stats.registrations_inconsistent},
                       {"registrations_missed", Optional(s.registrations_missed)},
                       {"dead_reckoning_scale_error", m.calibration.scale_error},
                       {"dead_reckoning_misalignment_rad", m.calibration.misalignment_rad},
                       {"loops_accepted", s.loops_accepted},
                       {"loops_rejected", s.loops_rejected},
                       {"loops_false", Optional(s.loops_false)},
                       {"loops_missed", Optional(s.loops_missed)},
                       {"navigation_noise_assumed", m.navigation_noise_assumed},
                       {"ate_slam_m", Optional(s.ate_slam_m)},
                       {"ate_dead_reckoning_m", Optional(s.ate_dead_reckoning_m)},
                       {"rpe_slam_per_m", Optional(s.rpe_slam_per_m)},
                       {"rpe_dead_reckoning_per_m", Optional(s.rpe_dead_reckoning_per_m)},
                       {"nees_mean", Optional(s.nees_mean)},
                       {"expected_map_error_m", Optional(m.expected_map_error_m)},
                       {"expected_position_error_m", Optional(m.expected_position_error_m)}};
  return report;
}

// Every output is checked before any work: a missing folder, or an output that is the input.
void RequireOutput(const std::string& path, const char* option, const std::string& log) {
  if (path.empty()) return;
  CheckOutputPath(path, option, {log});
}

void CheckMapOutputs(const MapArgs& a) {
  for (const auto& [path, option] : {std::pair{a.output, "-o"},
                                     {a.trajectory, "--trajectory"},
                                     {a.dead_reckoning, "--dead-reckoning"},
                                     {a.truth, "--truth"},
                                     {a.json, "--json"}}) {
    RequireOutput(path, option, a.log);
  }
  CheckCloudOutputPath(a.output, "-o", {a.log});
}

mapping::DiveMappingOptions DiveMappingOptionsOf(const MapArgs& a) {
  mapping::DiveMappingOptions options;
  options.map_voxel_m = a.voxel_m;
  options.mapper.sweeps_per_submap = a.sweeps_per_submap;
  options.mapper.threads = a.threads;
  options.mapper.max_navigation_gap_s = a.max_navigation_gap_s;
  options.mapper.windowed_solves = !a.whole_graph_solves;
  options.mapper.whole_solve_lag_s = a.whole_solve_lag_s;
  // Older submaps' clouds wait on disk, so a long dive's memory does not grow with it.
  options.mapper.spill_folder = TemporaryFolder();
  options.table_cache = TableCache();
  return options;
}

void WriteMapOutputs(const MapArgs& a, const mapping::DiveMapping& m) {
  perception::WriteCloud(a.output, m.map);
  if (!a.trajectory.empty()) mapping::WriteTum(a.trajectory, m.slam);
  if (!a.dead_reckoning.empty()) mapping::WriteTum(a.dead_reckoning, m.dead_reckoning);
  if (!a.truth.empty()) {
    if (m.truth.empty())
      throw Error("--truth " + a.truth + ": the log holds no ground truth (not simulated)");
    mapping::WriteTum(a.truth, m.truth);
  }
}

// What the dive's mapping did and cost: frames left out, registrations and loops, the dead
// reckoning's calibration and the stage times.
void PrintMapWork(const MapArgs& a, const mapping::DiveMapping& m, const mapping::MapSummary& s) {
  std::printf(
      "%s: %zu points, %d submaps over %.1f s of dive, mapped in %.2f s (%.0fx real time)\n",
      a.output.c_str(), m.map.size(), m.submaps, m.dive_duration_s, m.seconds, s.real_time_factor);
  if (m.stats.frames_without_navigation > 0) {
    std::printf(
        "%lld of %lld frames left out: not between navigation samples at most %g s apart "
        "(--max-navigation-gap)\n",
        static_cast<long long>(m.stats.frames_without_navigation),
        static_cast<long long>(m.stats.frames_without_navigation + m.stats.frames),
        a.max_navigation_gap_s);
  }
  std::printf(
      "registrations %d (%d left to navigation, %d of them inconsistent with it), loops accepted "
      "%d, rejected %d, not tried on %d submaps too plain to pin one\n",
      m.stats.registrations, m.stats.registrations_failed + m.stats.registrations_inconsistent,
      m.stats.registrations_inconsistent, s.loops_accepted, s.loops_rejected,
      m.stats.loops_not_tried_plain);
  std::printf("dead reckoning as estimated: speed scale error %+.2f %%, misalignment %+.2f mrad\n",
              100.0 * m.calibration.scale_error, 1000.0 * m.calibration.misalignment_rad);
  std::printf(
      "time: triangulation %.2f s, submaps %.2f s, registration %.2f s, loop closures %.2f s, "
      "graph %.2f s (%d whole solves, %d of them beside the dive, %d of the last submaps, %d of "
      "them back to a loop)\n",
      m.stats.stage_seconds.triangulation_s, m.stats.stage_seconds.submap_s,
      m.stats.stage_seconds.registration_s, m.stats.stage_seconds.loop_s,
      m.stats.stage_seconds.graph_s, m.stats.whole_solves, m.stats.whole_solves_beside,
      m.stats.window_solves, m.stats.loop_window_solves);
}

// What the map is worth: the errors its poses' uncertainty predicts and, for a simulated dive,
// the errors against the truth.
void PrintMapAccuracy(const mapping::DiveMapping& m, const mapping::MapSummary& s) {
  if (m.expected_map_error_m) {
    std::printf("expected map error from the poses' uncertainty: %.2f mm RMS along the normals\n",
                *m.expected_map_error_m * 1e3);
  }
  if (m.expected_position_error_m) {
    std::printf(
        "expected position error from the poses' uncertainty: %.2f mm RMS (what the ATE should "
        "come to)\n",
        *m.expected_position_error_m * 1e3);
  }
  if (m.navigation_noise_assumed) {
    std::printf("navigation noise: not recorded in the log (schema 1), a typical AUV's assumed\n");
  }
  if (s.ate_slam_m) {
    std::printf("against the truth: ATE dead reckoning %.4f m, SLAM %.4f m",
                *s.ate_dead_reckoning_m, *s.ate_slam_m);
    if (s.nees_mean) std::printf(", NEES %.2f (6 for a consistent covariance)", *s.nees_mean);
    std::printf("\n");
  }
}

void RunMap(const MapArgs& a) {
  CheckMapOutputs(a);
  if (a.whole_solve_lag_s > 0.0) UseOneMallocArena();
  if (a.threads > 0) omp_set_num_threads(a.threads);
  const mapping::DiveLogReader log(a.log);
  // Refused before anything is mapped or written: a real log has no truth to write.
  if (!a.truth.empty() && log.frame_count() > 0 && !log.ReadGroundTruth(0)) {
    throw Error("--truth " + a.truth + ": the log " + a.log +
                " holds no ground truth (not simulated)");
  }
  mapping::DiveMapping m;
  {
    ProgressBar bar;
    m = mapping::MapDive(log, DiveMappingOptionsOf(a), [&bar](double f) { bar.Update("map", f); });
  }
  WriteMapOutputs(a, m);
  const mapping::MapSummary s = mapping::Summarise(m);
  PrintMapWork(a, m, s);
  PrintMapAccuracy(m, s);
  if (!a.json.empty()) WriteJsonFile(a.json, MapReportJson(m, a.log, a.output));
}

}  // namespace

void AddMapCommand(CLI::App& app) {
  auto args = std::make_shared<MapArgs>();
  CLI::App* cmd = app.add_subcommand(
      "map",
      "scan-matching SLAM over a dive log: map, trajectories, per-pose uncertainty, loop closures");
  cmd->add_option("log", args->log, "dive log (.db)")->required()->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", args->output, "map to write (.ply or .pcd), voxelised")
      ->required();
  cmd->add_option("--trajectory", args->trajectory,
                  "SLAM trajectory to write (TUM: t tx ty tz qx qy qz qw)");
  cmd->add_option("--dead-reckoning", args->dead_reckoning,
                  "the navigation at the same times (TUM)");
  cmd->add_option("--truth", args->truth,
                  "the true trajectory at the same times (TUM; simulated logs)");
  cmd->add_option(
      "--json", args->json,
      "report: trajectories, per-pose covariance and standard deviations, loops, figures");
  cmd->add_option("--voxel", args->voxel_m, "map voxel, metres")
      ->capture_default_str()
      ->check(kPositiveNumber);
  cmd->add_option("--sweeps-per-submap", args->sweeps_per_submap, "sweeps grouped into one submap")
      ->capture_default_str()
      ->check(kPositiveNumber);
  cmd->add_option(
         "--max-navigation-gap", args->max_navigation_gap_s,
         "seconds: frames between navigation samples farther apart, or outside them, are left out "
         "(and counted)")
      ->capture_default_str()
      ->check(kPositiveNumber);
  cmd->add_flag("--whole-graph-solves", args->whole_graph_solves,
                "solve the whole pose graph at every loop and every few submaps, not only the last "
                "submaps and the loop's (slower as the dive grows; the map differs little)");
  cmd->add_option("--whole-solve-lag", args->whole_solve_lag_s,
                  "seconds of dive: a long dive's whole-graph solves run beside the mapping and "
                  "their answers are applied this much later (0: on the mapping thread, at once; "
                  "online inspection uses 10)")
      ->capture_default_str()
      ->check(kNonNegativeNumber);
  cmd->add_option("--threads", args->threads,
                  "threads (0: all cores); the output does not depend on it")
      ->check(kNonNegativeNumber);
  cmd->callback([args] { RunMap(*args); });
}

}  // namespace uwscan::app
