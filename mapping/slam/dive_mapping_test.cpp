#include "mapping/slam/dive_mapping.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "mapping/log/dive_log_test_support.hpp"
#include "mapping/log/dive_simulation.hpp"
#include "mapping/slam/live_map.hpp"
#include "mapping/slam/map_report.hpp"
#include "mapping/slam/navigation_uncertainty.hpp"
#include "mapping/slam/registration_information.hpp"
#include "mapping/slam/trajectory_metrics.hpp"
#include "scanner/sim/ray_caster.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"

namespace uwscan::mapping::test {
namespace {

scanner::sim::Scene ShortScene() {
  return scanner::sim::LoadScene(fs::path(UWSCAN_SOURCE_DIR_FOR_TESTS) /
                                 "data/scenes/inspection_short.yaml");
}

class DiveMappingTest : public DiveLogTest {
 protected:
  fs::path Simulate(const scanner::sim::Scene& scene, const char* name) {
    const fs::path path = dir_ / name;
    const scanner::sim::Simulator simulator(scene);
    DiveSimulationOptions options;
    options.threads = 2;
    SimulateDive(simulator, "", path, options);
    return path;
  }
  DiveMappingOptions Options(int threads = 2) const {
    DiveMappingOptions options;
    options.mapper.threads = threads;
    options.table_cache = dir_ / "tables";
    return options;
  }
  DiveMapping Map(const fs::path& path, int threads = 2) {
    return MapDive(DiveLogReader(path), Options(threads));
  }
};

void ExpectSameBits(const DiveMapping& a, const DiveMapping& b) {
  ASSERT_EQ(a.slam.size(), b.slam.size());
  for (std::size_t i = 0; i < a.slam.size(); ++i) ExpectSamePose(a.slam[i].T_W_V, b.slam[i].T_W_V);
  ASSERT_EQ(a.map.size(), b.map.size());
  for (std::size_t i = 0; i < a.map.size(); ++i) {
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(std::bit_cast<std::uint32_t>(a.map.points[i][k]),
                std::bit_cast<std::uint32_t>(b.map.points[i][k]));
  }
  ASSERT_EQ(a.loops.size(), b.loops.size());
  ASSERT_EQ(a.covariances.size(), b.covariances.size());
  for (std::size_t i = 0; i < a.covariances.size(); ++i) {
    for (int k = 0; k < 36; ++k) {
      EXPECT_EQ(std::bit_cast<std::uint64_t>(a.covariances[i](k)),
                std::bit_cast<std::uint64_t>(b.covariances[i](k)))
          << "pose " << i;
    }
  }
  ASSERT_TRUE(a.expected_map_error_m && b.expected_map_error_m);
  EXPECT_EQ(std::bit_cast<std::uint64_t>(*a.expected_map_error_m),
            std::bit_cast<std::uint64_t>(*b.expected_map_error_m));
}

// The largest distance between two mappings' positions of the same submap (metres).
double LargestPositionDifference(const DiveMapping& a, const DiveMapping& b) {
  EXPECT_EQ(a.slam.size(), b.slam.size());
  double largest_m = 0.0;
  for (std::size_t i = 0; i < std::min(a.slam.size(), b.slam.size()); ++i) {
    largest_m =
        std::max(largest_m, (a.slam[i].T_W_V.translation() - b.slam[i].T_W_V.translation()).norm());
  }
  return largest_m;
}

TEST_F(DiveMappingTest, WithoutDriftTheMapLiesOnTheTruth) {
  scanner::sim::Scene scene = ShortScene();
  scene.effects.navigation_drift.on = false;
  scene.effects.peak_noise.on = false;
  const DiveMapping m = Map(Simulate(scene, "exact.db"));
  ASSERT_GT(m.submaps, 5);
  ASSERT_EQ(m.truth.size(), m.slam.size());
  EXPECT_LT(AbsoluteTrajectoryError(m.slam, m.truth), 5e-4);
  EXPECT_LT(AbsoluteTrajectoryError(m.dead_reckoning, m.truth), 1e-9);
  EXPECT_GT(m.map.size(), 10000u);
}

TEST_F(DiveMappingTest, SameBitsForOneAndTwoThreadsAndOnlineOrOffline) {
  const fs::path log = Simulate(ShortScene(), "drift.db");
  const DiveMapping one = Map(log, 1), two = Map(log, 2);
  ExpectSameBits(one, two);

  // Online: the same log fed as a live vehicle would, navigation far ahead of the frames.
  const DiveLogReader reader(log);
  MapperOptions options;
  options.threads = 2;
  Mapper mapper(reader.header().scanner, reader.header().scan_pattern, *reader.vehicle_mount(),
                *reader.header().navigation_noise, options, dir_ / "tables");
  for (const NavigationRecord& nav : reader.ReadNavigation()) mapper.AddNavigation(nav);
  reader.ForEachFrame(
      [&](const FrameRecord& frame, const GroundTruthRecord*) { mapper.AddFrame(frame); }, false);
  mapper.Finish();
  ASSERT_EQ(mapper.submap_count(), two.submaps);
  for (int i = 0; i < mapper.submap_count(); ++i)
    ExpectSamePose(two.slam[static_cast<size_t>(i)].T_W_V, mapper.pose(i));
  // The same loops and the same map, point for point.
  ASSERT_EQ(mapper.loops().size(), two.loops.size());
  for (std::size_t k = 0; k < two.loops.size(); ++k) {
    EXPECT_EQ(mapper.loops()[k].accepted, two.loops[k].accepted) << "loop " << k;
  }
  const perception::PointCloud online_map = mapper.Map(DiveMappingOptions{}.map_voxel_m);
  EXPECT_EQ(online_map.origin, two.map.origin);
  ASSERT_EQ(online_map.size(), two.map.size());
  for (std::size_t i = 0; i < online_map.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(std::bit_cast<std::uint32_t>(online_map.points[i][k]),
                std::bit_cast<std::uint32_t>(two.map.points[i][k]))
          << "map point " << i;
    }
  }
}

// Solves of the last few submaps (and a loop's) during the dive, the whole graph at Finish: the
// same trajectory as whole-graph solves throughout, to a fraction of its error.
TEST_F(DiveMappingTest, WindowedSolvesMapAsWholeGraphSolvesDo) {
  const fs::path log = Simulate(ShortScene(), "drift.db");
  DiveMappingOptions options = Options();
  options.mapper.solve_window_submaps = 4;
  options.mapper.solve_window_max_submaps = 8;
  const DiveMapping windowed = MapDive(DiveLogReader(log), options);
  options.mapper.windowed_solves = false;
  const DiveMapping whole = MapDive(DiveLogReader(log), options);
  EXPECT_GT(windowed.stats.window_solves, windowed.stats.whole_solves);
  EXPECT_EQ(whole.stats.window_solves, 0);
  const double largest_m = LargestPositionDifference(windowed, whole);
  const double ate_whole = AbsoluteTrajectoryError(whole.slam, whole.truth);
  const double ate_windowed = AbsoluteTrajectoryError(windowed.slam, windowed.truth);
  std::printf("largest difference %.2f mm; ATE %.2f mm windowed, %.2f mm whole\n", largest_m * 1e3,
              ate_windowed * 1e3, ate_whole * 1e3);
  EXPECT_LT(largest_m, 0.5 * ate_whole);
  EXPECT_LT(ate_windowed, 1.05 * ate_whole);
}

// A long dive's whole solves beside the mapping (MapperOptions::whole_solve_lag_s; the short
// windows make this dive's graph long enough for them): the same bits whether the mapping runs
// on one thread or two (so however fast it runs against the solving thread), and the same
// trajectory as whole solves made at once on the mapping thread, to a fraction of its error.
TEST_F(DiveMappingTest, WholeSolvesBesideTheDiveMapAsThoseMadeAtOnce) {
  const fs::path log = Simulate(ShortScene(), "drift.db");
  auto map_with = [&](double lag_s, int threads) {
    DiveMappingOptions options = Options(threads);
    options.mapper.solve_window_submaps = 4;
    options.mapper.solve_window_max_submaps = 8;
    options.mapper.whole_solve_lag_s = lag_s;
    return MapDive(DiveLogReader(log), options);
  };
  const DiveMapping at_once = map_with(0.0, 2), beside = map_with(2.0, 2),
                    beside_one_thread = map_with(2.0, 1);
  EXPECT_EQ(at_once.stats.whole_solves_beside, 0);
  EXPECT_GE(beside.stats.whole_solves_beside, 3);
  EXPECT_EQ(beside.stats.whole_solves, at_once.stats.whole_solves);
  ExpectSameBits(beside, beside_one_thread);
  const double largest_m = LargestPositionDifference(beside, at_once);
  const double ate_at_once = AbsoluteTrajectoryError(at_once.slam, at_once.truth);
  const double ate_beside = AbsoluteTrajectoryError(beside.slam, beside.truth);
  std::printf(
      "whole solves %d (%d beside); largest difference %.2f mm; ATE %.2f mm beside, %.2f mm "
      "at once\n",
      beside.stats.whole_solves, beside.stats.whole_solves_beside, largest_m * 1e3,
      ate_beside * 1e3, ate_at_once * 1e3);
  EXPECT_LT(largest_m, 0.5 * ate_at_once);
  EXPECT_LT(ate_beside, 1.05 * ate_at_once);
}

// The clouds of all but the last few submaps, and the graph's measurements among submaps no
// window frees any more, spilled to disk and read back for loops, the whole solves and the map:
// the same bits as with everything in memory.
TEST_F(DiveMappingTest, SpilledSubmapsMapToTheSameBits) {
  const fs::path log = Simulate(ShortScene(), "drift.db");
  DiveMappingOptions options = Options();
  // Windows short enough for this dive to leave measurements behind them (PoseGraph retires a
  // few hundred at once: about fifty submaps' worth).
  options.mapper.solve_window_submaps = 4;
  options.mapper.solve_window_max_submaps = 8;
  const DiveMapping in_memory = MapDive(DiveLogReader(log), options);
  ASSERT_GT(in_memory.submaps, 8 + 2 * static_cast<int>(PoseGraph::kRetireAtOnce) / 5);
  options.mapper.spill_folder = dir_;
  options.mapper.resident_submaps = 4;
  const DiveMapping spilled = MapDive(DiveLogReader(log), options);
  EXPECT_GT(spilled.loops.size(), 0u);
  ExpectSameBits(spilled, in_memory);
}

void ExpectSameCloud(const perception::PointCloud& a, const perception::PointCloud& b,
                     const std::string& what) {
  ASSERT_EQ(a.origin, b.origin) << what;
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(std::bit_cast<std::uint32_t>(a.points[i][k]),
                std::bit_cast<std::uint32_t>(b.points[i][k]))
          << what << ", point " << i;
    }
  }
}

// The live map (what the ROS node publishes every few seconds) keeps merged what has not moved
// since the last map: after every submap of a dive with short windows and spilled clouds, the
// same map to the bit as merging every submap again. Two dives: one with several whole solves,
// one where loops free the submaps back to their older end, further back than the last solve's
// window (TheLiveMapFollowsLoopsBackToTheirOlderEnd, after OutAndBackOverAPipe).
class LiveMapTest : public DiveMappingTest {
 protected:
  struct Run {
    int compared = 0, last_first_movable = 0;
    int rebuilding = 0;  // submaps after which the map rebuilt in batches was not complete yet
    MapperStats stats;
  };
  Run CompareLiveMaps(const fs::path& log, const MapperOptions& mapper_options, const char* name) {
    const DiveLogReader reader(log);
    MapperOptions options = mapper_options;
    options.spill_folder = dir_ / name;
    fs::create_directories(options.spill_folder);
    options.resident_submaps = 4;
    Mapper mapper(reader.header().scanner, reader.header().scan_pattern, *reader.vehicle_mount(),
                  *reader.header().navigation_noise, options, dir_ / name / "tables");
    const double voxel_m = DiveMappingOptions{}.map_voxel_m;
    // Settled submaps taken up often; and never, so that only solves move the steady part.
    LiveMap live(voxel_m, 3), live_unsettled(voxel_m, 1000);
    // After a whole solve the settled part merged anew 3 submaps per Build: the whole map again
    // once that is done, and meanwhile (rebuilding) never for longer than the batches need. Built
    // into one cloud from start to end, as the node does.
    LiveMap live_in_batches(voxel_m, 3, 3);
    perception::PointCloud batched;
    for (const NavigationRecord& nav : reader.ReadNavigation()) mapper.AddNavigation(nav);
    Run run;
    reader.ForEachFrame(
        [&](const FrameRecord& frame, const GroundTruthRecord*) {
          const int before = mapper.submap_count();
          mapper.AddFrame(frame);
          if (mapper.submap_count() == before) return;
          const perception::PointCloud map = mapper.Map(voxel_m);
          const std::string when = "after submap " + std::to_string(mapper.submap_count());
          ExpectSameCloud(live.Build(mapper), map, when);
          ExpectSameCloud(live_unsettled.Build(mapper), map, when + " (never settled)");
          live_in_batches.Build(mapper, batched);
          if (live_in_batches.rebuilding()) {
            ++run.rebuilding;
          } else {
            ExpectSameCloud(batched, map, when + " (rebuilt in batches)");
          }
          run.last_first_movable = mapper.FirstMovableSubmap();
          ++run.compared;
        },
        false);
    mapper.Finish();
    ExpectSameCloud(live.Build(mapper), mapper.Map(voxel_m), "after Finish");
    ExpectSameCloud(live_unsettled.Build(mapper), mapper.Map(voxel_m), "after Finish");
    live_in_batches.Build(mapper, batched);
    for (int build = 0; live_in_batches.rebuilding() && build <= mapper.submap_count() / 3; ++build)
      live_in_batches.Build(mapper, batched);
    EXPECT_FALSE(live_in_batches.rebuilding());
    ExpectSameCloud(batched, mapper.Map(voxel_m), "after Finish (rebuilt in batches)");
    run.stats = mapper.stats();
    return run;
  }
};

TEST_F(LiveMapTest, TheLiveMapIsTheWholeMapToTheBit) {
  const fs::path log = Simulate(ShortScene(), "drift.db");
  MapperOptions options;
  options.solve_window_submaps = 4;
  options.solve_window_max_submaps = 8;
  const Run whole = CompareLiveMaps(log, options, "whole");
  EXPECT_GT(whole.compared, 30);
  // The dive had what the live map must follow: submaps settled, and whole solves after them.
  EXPECT_GT(whole.last_first_movable, 25);
  EXPECT_GE(whole.stats.whole_solves, 3);
  EXPECT_GT(whole.rebuilding, 0);
}

TEST_F(DiveMappingTest, TheCovarianceIsConsistentAndNoLoopIsFalse) {
  const DiveMapping m = Map(Simulate(ShortScene(), "drift.db"));
  const MapSummary s = Summarise(m);
  ASSERT_TRUE(s.nees_mean.has_value());
  EXPECT_GT(*s.nees_mean, 0.5 * 6.0);
  EXPECT_LT(*s.nees_mean, 3.0 * 6.0);
  EXPECT_EQ(s.loops_false.value_or(-1), 0);
  for (const Matrix6d& c : m.covariances) EXPECT_GT(PoseStd(c).head<2>().minCoeff(), 0.0);
  // The ATE is what the covariance predicts for it (one dive: one draw of the errors).
  ASSERT_TRUE(m.expected_position_error_m.has_value() && s.ate_slam_m.has_value());
  EXPECT_GT(*s.ate_slam_m, 0.5 * *m.expected_position_error_m)
      << *s.ate_slam_m << " m, " << *m.expected_position_error_m;
  EXPECT_LT(*s.ate_slam_m, 2.0 * *m.expected_position_error_m)
      << *s.ate_slam_m << " m, " << *m.expected_position_error_m;
}

// The MEMS scanner's dive (the same lap, pre-curved lines instead of a galvanometer's fan):
// without drift the map lies on the truth; with drift and peak noise the registrations agree
// with the navigation and the covariance is honest. (One lap has no loop to beat dead
// reckoning with: the looping MEMS dive is in bench slam.)
TEST_F(DiveMappingTest, AMemsDiveMapsAsAGalvanometerDiveDoes) {
  scanner::sim::Scene scene = scanner::sim::LoadScene(fs::path(UWSCAN_SOURCE_DIR_FOR_TESTS) /
                                                      "data/scenes/inspection_mems.yaml");
  ASSERT_EQ(scene.scanner.model.kind(), scanner::ScannerKind::kMems);
  {
    scanner::sim::Scene exact = scene;
    exact.effects.navigation_drift.on = false;
    exact.effects.peak_noise.on = false;
    const DiveMapping m = Map(Simulate(exact, "mems_exact.db"));
    ASSERT_GT(m.submaps, 30);
    EXPECT_LT(AbsoluteTrajectoryError(m.slam, m.truth), 1e-3);
  }
  const DiveMapping m = Map(Simulate(scene, "mems_drift.db"));
  const MapSummary s = Summarise(m);
  EXPECT_LE(m.stats.registrations_inconsistent, m.submaps / 10);
  EXPECT_GE(m.stats.registrations, 3 * m.submaps / 4);
  ASSERT_TRUE(s.ate_slam_m && s.nees_mean && m.expected_position_error_m);
  EXPECT_GT(*s.ate_slam_m, 0.5 * *m.expected_position_error_m)
      << *s.ate_slam_m << " m, " << *m.expected_position_error_m;
  EXPECT_LT(*s.ate_slam_m, 2.0 * *m.expected_position_error_m)
      << *s.ate_slam_m << " m, " << *m.expected_position_error_m;
  EXPECT_EQ(s.loops_false.value_or(-1), 0);
  EXPECT_GT(*s.nees_mean, 0.5 * 6.0);
  EXPECT_LT(*s.nees_mean, 3.0 * 6.0);
}

TEST_F(DiveMappingTest, TheMapsExpectedErrorIsWhatItsDistanceToTheTruthComesTo) {
  const scanner::sim::Scene scene = ShortScene();
  const DiveMapping m = Map(Simulate(scene, "drift.db"));
  ASSERT_TRUE(m.expected_map_error_m.has_value());
  // The map's distance to the scene's true surfaces, against what its poses' covariance says.
  const scanner::sim::RayCaster caster(scene.objects);
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < m.map.size(); i += 7) {
    const double d = caster.DistanceToSurface(m.map.Point(i), 0.5).value_or(0.5);
    sum += d * d;
    ++count;
  }
  const double measured = std::sqrt(sum / static_cast<double>(count));
  EXPECT_GT(measured, 0.6 * *m.expected_map_error_m)
      << measured << " m measured, " << *m.expected_map_error_m;
  EXPECT_LT(measured, 1.5 * *m.expected_map_error_m)
      << measured << " m measured, " << *m.expected_map_error_m;
}

TEST_F(DiveMappingTest, AlongASinglePipeTheMapFollowsTheNavigation) {
  // Out along the pipe only: scan matching sees a pipe on a plane, free along the pipe (x).
  scanner::sim::Scene scene = scanner::sim::LoadScene(fs::path(UWSCAN_SOURCE_DIR_FOR_TESTS) /
                                                      "data/scenes/inspection_pipe.yaml");
  scene.scanner.sweeps = 40;
  const DiveMapping m = Map(Simulate(scene, "pipe.db"));
  ASSERT_EQ(m.truth.size(), m.slam.size());
  for (std::size_t i = 0; i < m.slam.size(); ++i) {
    const double slam_x =
        std::abs(m.slam[i].T_W_V.translation().x() - m.truth[i].T_W_V.translation().x());
    const double dr_x =
        std::abs(m.dead_reckoning[i].T_W_V.translation().x() - m.truth[i].T_W_V.translation().x());
    EXPECT_LT(slam_x, dr_x + 0.01) << "submap " << i;
  }
  EXPECT_LE(AbsoluteTrajectoryError(m.slam, m.truth),
            AbsoluteTrajectoryError(m.dead_reckoning, m.truth) + 0.005);
}

// The pipe dive, out 3 m instead of 8 and back: coming back over the pipe closes loops that see
// it without its ends.
scanner::sim::Scene OutAndBackOverAPipe() {
  scanner::sim::Scene scene = scanner::sim::LoadScene(fs::path(UWSCAN_SOURCE_DIR_FOR_TESTS) /
                                                      "data/scenes/inspection_pipe.yaml");
  std::vector<scanner::sim::TrajectoryPose>& poses = scene.trajectory.poses;
  if (poses.size() != 5u) {  // out, turning (two), back
    ADD_FAILURE() << "inspection_pipe.yaml has " << poses.size() << " poses, not 5";
    return scene;
  }
  const double shift_s = 20.0;  // 8 m at 0.25 m/s is 32 s; 3 m is 12 s
  for (std::size_t i = 1; i < poses.size(); ++i)
    poses[i].time_s -= i == 4 ? 2.0 * shift_s : shift_s;
  for (std::size_t i = 1; i < 4; ++i) poses[i].T_W_V.translation().x() = 3.0;
  scene.scanner.sweeps = static_cast<int>(poses.back().time_s / 70.0 * scene.scanner.sweeps);
  return scene;
}

TEST_F(LiveMapTest, TheLiveMapFollowsLoopsBackToTheirOlderEnd) {
  MapperOptions options;
  options.solve_window_submaps = 2;
  options.solve_window_max_submaps = 30;
  options.loop_window_chi2_per_direction = 0.0;  // every loop frees back to its older end
  options.full_solve_growth = 1e6;
  const Run run =
      CompareLiveMaps(Simulate(OutAndBackOverAPipe(), "pipe_loop.db"), options, "loops");
  EXPECT_GT(run.stats.loop_window_solves, 3);
}

TEST_F(DiveMappingTest, OutAndBackOverAPipeLoopsPinAllButTheSlide) {
  // The loops are kept in the five directions they pin and bring the sideways drift of the dead
  // reckoning back onto the pipe; along it they claim nothing.
  const DiveMapping m = Map(Simulate(OutAndBackOverAPipe(), "pipe_loop.db"));
  ASSERT_EQ(m.truth.size(), m.slam.size());
  int accepted = 0;
  for (const LoopClosure& loop : m.loops) {
    if (!loop.accepted) continue;
    ++accepted;
    EXPECT_GE(loop.constrained_directions, 5) << loop.from << " -> " << loop.to;
    if (loop.constrained_directions == 6) continue;  // it saw the pipe's end
    // What it leaves free is a slide along the pipe: x of the earlier submap, which flew along
    // it, to within the heading error.
    const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(loop.information);
    EXPECT_LT(eigen.eigenvalues()(0), 1e-9 * eigen.eigenvalues()(5));
    const Vector6d free = eigen.eigenvectors().col(0);
    EXPECT_LT(free.head<3>().norm(), 1e-6);
    EXPECT_GT(std::abs(free(3)), std::cos(0.02)) << loop.from << " -> " << loop.to;
  }
  EXPECT_GT(accepted, 5);
  // Coming back, each loop spans a longer chain than the one before (to the start of the dive).
  // Along that chain the prediction would widen twofold by the last loop (19 -> 39 mm); through
  // the loop before it, by a fifth: the slide along the pipe, which loops leave to the chain.
  std::vector<double> prediction_std_m;
  for (const LoopClosure& loop : m.loops) {
    if (loop.accepted) prediction_std_m.push_back(loop.prediction_std_m);
  }
  ASSERT_GT(prediction_std_m.size(), 5u);
  EXPECT_LT(prediction_std_m.back(), 1.5 * prediction_std_m.front());
  EXPECT_EQ(Summarise(m).loops_false.value_or(-1), 0);
  double slam_sideways = 0.0, dr_sideways = 0.0;
  for (std::size_t i = 0; i < m.slam.size(); ++i) {
    const double y = m.truth[i].T_W_V.translation().y();
    slam_sideways = std::max(slam_sideways, std::abs(m.slam[i].T_W_V.translation().y() - y));
    dr_sideways = std::max(dr_sideways, std::abs(m.dead_reckoning[i].T_W_V.translation().y() - y));
  }
  EXPECT_LT(slam_sideways, 0.5 * dr_sideways);
}

// A dive of two submaps, the second `x_m` along x and `dt_s` after the first, mapped exactly: what
// the summary's truth checks read.
DiveMapping TwoSubmapDive(double x_m, double dt_s) {
  DiveMapping m;
  Eigen::Isometry3d second = Eigen::Isometry3d::Identity();
  second.translation().x() = x_m;
  m.truth = {{0.0, Eigen::Isometry3d::Identity()}, {dt_s, second}};
  m.slam = m.dead_reckoning = m.truth;
  return m;
}

TEST(MapSummary, ALoopIsJudgedOnlyInTheDirectionsItMeasures) {
  DiveMapping m = TwoSubmapDive(1.0, 1.0);
  const Eigen::Isometry3d far = m.truth[1].T_W_V;
  LoopClosure slid;  // off by 20 cm along the pipe it cannot see along
  slid.from = 0;
  slid.to = 1;
  slid.accepted = true;
  slid.T_from_to = far;
  slid.T_from_to.translation().x() += 0.2;
  slid.information.diagonal() << 1e6, 1e6, 1e6, 0.0, 1e6, 1e6;
  m.loops = {slid};
  EXPECT_EQ(Summarise(m).loops_false.value_or(-1), 0);
  LoopClosure sideways = slid;  // off by 20 cm across it: a wrong association
  sideways.T_from_to = far;
  sideways.T_from_to.translation().y() += 0.2;
  m.loops = {slid, sideways};
  EXPECT_EQ(Summarise(m).loops_false.value_or(-1), 1);
}

TEST(MapSummary, ARightLoopTurnedAwayByThePredictionCountsAsMissed) {
  DiveMapping m = TwoSubmapDive(1.0, 1.0);
  const Eigen::Isometry3d far = m.truth[1].T_W_V;
  LoopClosure right;  // 1 cm off: within the tolerance
  right.from = 0;
  right.to = 1;
  right.T_from_to = far;
  right.T_from_to.translation().y() += 0.01;
  right.information.diagonal().setConstant(1e6);
  right.reason = std::string(kInconsistentLoop) + ": chi2 30 in 6 directions";
  LoopClosure wrong = right;  // 20 cm off: rightly rejected
  wrong.T_from_to.translation().y() += 0.2;
  LoopClosure unfit = right;  // rejected for another reason: not the chi-square's doing
  unfit.reason = "fitness 0.3 below 0.5";
  LoopClosure kept = right;
  kept.accepted = true;
  kept.reason.clear();
  m.loops = {right, wrong, unfit, kept};
  const MapSummary s = Summarise(m);
  EXPECT_EQ(s.loops_missed.value_or(-1), 1);
  EXPECT_EQ(s.loops_false.value_or(-1), 0);
  m.truth.clear();
  EXPECT_FALSE(Summarise(m).loops_missed.has_value());
}

TEST(MapSummary, ARightRegistrationTurnedAwayCountsAsMissedOnlyWhereTheNavigationWasFurtherOff) {
  DiveMapping m = TwoSubmapDive(0.3, 0.5);
  const Eigen::Isometry3d step = m.truth[1].T_W_V;
  InconsistentRegistration right;  // 1 mm off, the navigation 24 mm
  right.from = 0;
  right.to = 1;
  right.T_from_to = right.T_predicted = step;
  right.T_from_to.translation().y() += 0.001;
  right.T_predicted.translation().x() += 0.024;
  right.information.diagonal().setConstant(1e6);
  InconsistentRegistration worse = right;  // 4 cm off where the navigation is 24 mm: a wrong one
  worse.T_from_to.translation().y() += 0.039;
  InconsistentRegistration slid = right;  // off along the slide it leaves free: judged without it
  slid.T_from_to.translation().x() += 0.1;
  slid.information(3, 3) = 0.0;
  slid.T_predicted.translation().x() = 0.3;
  slid.T_predicted.translation().z() += 0.01;
  m.inconsistent_registrations = {right, worse, slid};
  EXPECT_EQ(Summarise(m).registrations_missed.value_or(-1), 2);
  m.truth.clear();
  EXPECT_FALSE(Summarise(m).registrations_missed.has_value());
}

// A log of the short dive's first `frames` frames, with the navigation samples `keep` accepts.
// The navigation the simulator gives at 20 Hz (the samples `keep` passes) and its first
// `frames` frames, appended to `writer` as a recorder would.
void AppendDive(const scanner::sim::Simulator& simulator, DiveLogWriter& writer,
                std::int64_t frames, const std::function<bool(double)>& keep) {
  writer.SetVehicleMount(simulator.scene().trajectory.T_V_C);
  for (const scanner::sim::NavigationSample& n : simulator.Navigation(20.0)) {
    if (keep(n.time_s)) writer.AppendNavigation({n.time_s, n.T_W_V});
  }
  for (std::int64_t i = 0; i < frames; ++i) {
    const scanner::sim::SimulatedFrame f = simulator.Frame(i);
    FrameRecord record;
    record.time_s = f.time_s;
    record.command = f.command;
    record.sweep = f.sweep;
    record.peaks_px = f.peaks_px;
    writer.AppendFrame(record);
  }
}

DiveLogHeader HeaderWithNavigationNoise(const scanner::sim::Simulator& simulator) {
  DiveLogHeader header;
  header.scanner = simulator.scanner();
  header.scan_pattern = simulator.scan_pattern();
  header.navigation_noise = NavigationNoise{0.003, 0.0005, 0.01, 0.01, 0.001, 0.0005};
  return header;
}

fs::path WriteLogWithNavigation(const scanner::sim::Simulator& simulator, const fs::path& path,
                                std::int64_t frames, const std::function<bool(double)>& keep) {
  DiveLogWriter writer(path, HeaderWithNavigationNoise(simulator));
  AppendDive(simulator, writer, frames, keep);
  return path;
}

TEST_F(DiveMappingTest, ALogCutShortMapsUpToItsLastFrame) {
  // A recorder that died mid-sweep: every navigation sample, the frames up to the crash.
  const scanner::sim::Simulator simulator(ShortScene());
  const std::int64_t kept = simulator.frame_count() / 2 + 7;
  const fs::path path =
      WriteLogWithNavigation(simulator, dir_ / "cut.db", kept, [](double) { return true; });
  const DiveMapping m = Map(path);
  EXPECT_TRUE(m.truth.empty());
  ASSERT_GT(m.submaps, 2);
  EXPECT_NEAR(m.dive_duration_s, static_cast<double>(kept - 1) * simulator.frame_period_s(), 1e-9);
  EXPECT_GT(m.slam.back().time_s, m.dive_duration_s - 2.0);
}

// The recorder's process killed (SIGKILL) mid-dive: it never closed the log, whose last frames
// are still in SQLite's write-ahead log. The map goes up to the last frame it committed.
TEST_F(DiveMappingTest, ALogWhoseRecorderWasKilledMapsUpToItsLastFrame) {
  const scanner::sim::Simulator simulator(ShortScene());
  const std::int64_t kept = simulator.frame_count() / 2 + 7;
  const fs::path path = dir_ / "killed.db";
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // the recorder: writes, says so, and waits to be killed
    ::close(fds[0]);
    try {
      DiveLogWriter writer(path, HeaderWithNavigationNoise(simulator));
      AppendDive(simulator, writer, kept, [](double) { return true; });
      const char written = 1;
      if (::write(fds[1], &written, 1) != 1) ::_exit(1);
      for (;;) ::pause();
    } catch (...) {
      ::_exit(1);
    }
  }
  ::close(fds[1]);
  char written = 0;
  const bool reported = ::read(fds[0], &written, 1) == 1;
  ::close(fds[0]);
  ::kill(child, SIGKILL);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(reported) << "the recorder process stopped before writing its frames";
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
      << "the recorder exited " << status;
  ASSERT_TRUE(fs::exists(path.string() + "-wal"));  // never closed: its frames are in the WAL

  const DiveMapping m = Map(path);
  ASSERT_GT(m.submaps, 2);
  EXPECT_NEAR(m.dive_duration_s, static_cast<double>(kept - 1) * simulator.frame_period_s(), 1e-9);
  EXPECT_GT(m.slam.back().time_s, m.dive_duration_s - 2.0);
}

TEST_F(DiveMappingTest, FramesTheNavigationDoesNotCoverAreLeftOutAndCounted) {
  // The navigation drops out for 3 s (a DVL that lost the bottom) and stops 3 s before the
  // recorder: those frames have no pose to be placed with, and holding or bridging one would
  // smear the map without a word.
  const scanner::sim::Simulator simulator(ShortScene());
  const double period = simulator.frame_period_s();
  const std::int64_t frames = static_cast<std::int64_t>(12.0 / period);
  const auto kept = [](double t) { return t <= 9.0 && !(t > 3.0 && t < 6.0); };
  const fs::path path = WriteLogWithNavigation(simulator, dir_ / "dropout.db", frames, kept);
  // Covered: a sample at or before the frame and one at or after it, at most 1 s apart.
  std::vector<double> samples;
  for (const scanner::sim::NavigationSample& n : simulator.Navigation(20.0)) {
    if (kept(n.time_s)) samples.push_back(n.time_s);
  }
  std::int64_t uncovered = 0;
  for (std::int64_t i = 0; i < frames; ++i) {
    const double t = simulator.Frame(i).time_s;
    const auto after = std::lower_bound(samples.begin(), samples.end(), t);
    const bool covered =
        after != samples.end() &&
        (*after == t || (after != samples.begin() && *after - *(after - 1) <= 1.0));
    uncovered += covered ? 0 : 1;
  }
  ASSERT_GT(uncovered, frames / 3);

  const DiveMapping m = Map(path);
  EXPECT_EQ(m.stats.frames_without_navigation, uncovered);
  EXPECT_EQ(m.stats.frames + m.stats.frames_without_navigation, frames);
  for (const TimedPose& p : m.slam) {
    EXPECT_LE(p.time_s, 9.0);
    EXPECT_FALSE(p.time_s > 3.0 && p.time_s < 6.0)
        << "a submap anchored in the dropout, at " << p.time_s << " s";
  }

  // With every frame after the navigation's end nothing can be placed, and the error says why.
  const fs::path late =
      WriteLogWithNavigation(simulator, dir_ / "late.db", static_cast<std::int64_t>(2.0 / period),
                             [](double t) { return t >= 5.0; });
  EXPECT_NE(
      MessageOf([&] { Map(late); }).find("no frame lies within its navigation (samples from 5.0"),
      std::string::npos)
      << MessageOf([&] { Map(late); });
}

TEST_F(DiveMappingTest, UnusableLogsGiveAClearError) {
  const fs::path empty_nav = dir_ / "no_nav.db";
  {
    DiveLogWriter writer(empty_nav, TestHeader());
    for (int i = 0; i < 3; ++i) writer.AppendFrame(TestFrame(i, 10));
  }
  EXPECT_NE(MessageOf([&] { Map(empty_nav); }).find("has no navigation"), std::string::npos);

  const fs::path one = dir_ / "one.db";
  {
    DiveLogWriter writer(one, TestHeader());
    writer.AppendFrame(TestFrame(0, 10));
    writer.AppendNavigation({0.0, Eigen::Isometry3d::Identity()});
  }
  EXPECT_NE(MessageOf([&] { Map(one); }).find("has 1 frame"), std::string::npos);

  const std::string next = std::to_string(kDiveLogSchemaVersion + 1);
  RawExec(one, "UPDATE meta SET value = " + next + " WHERE key = 'schema_version'");
  EXPECT_NE(MessageOf([&] { Map(one); })
                .find("schema version " + next + ", this uwscan reads 1 to " +
                      std::to_string(kDiveLogSchemaVersion)),
            std::string::npos);
}

TEST_F(DiveMappingTest, VersionOneLogsOpenAndMapWithAnAssumedNoise) {
  scanner::sim::Scene scene = ShortScene();
  scene.scanner.sweeps = 12;
  const fs::path path = Simulate(scene, "v1.db");
  EXPECT_TRUE(DiveLogReader(path).header().navigation_noise.has_value());
  RawExec(path,
          "DROP TABLE navigation_noise; UPDATE meta SET value = 1 WHERE key = 'schema_version'");
  const DiveLogReader reader(path);
  EXPECT_EQ(reader.header().schema_version, 1);
  EXPECT_FALSE(reader.header().navigation_noise.has_value());
  const DiveMapping m = Map(path);
  EXPECT_TRUE(m.navigation_noise_assumed);
  EXPECT_GT(m.submaps, 1);
}

TEST(NavigationUncertainty, OdometryLeavesDepthRollAndPitchToThePriors) {
  const NavigationUncertainty model(NavigationNoise{0.003, 0.0005, 0.01, 0.01, 0.001, 0.0005});
  Eigen::Isometry3d a = Eigen::Isometry3d::Identity(), b = Eigen::Isometry3d::Identity();
  a.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  b.translation() = Eigen::Vector3d(0.5, 0.1, 0.0);
  const Matrix6d info = model.OdometryInformation(a, b, 2.0);
  // In a's frame the world's down axis is still z (a turns about it): z, roll and pitch free.
  Vector6d down = Vector6d::Zero();
  down(5) = 1.0;
  EXPECT_NEAR(down.dot(info * down), 0.0, 1e-9);
  Vector6d roll = Vector6d::Zero();
  roll(0) = 1.0;
  EXPECT_NEAR(roll.dot(info * roll), 0.0, 1e-9);
  Vector6d yaw = Vector6d::Zero();
  yaw(2) = 1.0;
  EXPECT_GT(yaw.dot(info * yaw), 1e5);
}

// A submap whose own surface pins two directions fewer than a loop must (a registration may pin
// one more than the whole surface) is not tried: on the pipe dive the turn over bare seabed
// (three directions) is passed over, and the loops back over the pipe (five) are still tried and
// closed.
TEST_F(DiveMappingTest, LoopsAreTriedOnlyFromSubmapsWhoseSurfaceCanPinThem) {
  DiveMappingOptions options = Options();
  options.keep_submaps = true;
  const DiveMapping m =
      MapDive(DiveLogReader(Simulate(OutAndBackOverAPipe(), "pipe_loop.db")), options);
  ASSERT_EQ(m.submap_clouds.size(), static_cast<std::size_t>(m.submaps));
  EXPECT_GT(m.stats.loops_not_tried_plain, 0);
  int accepted = 0;
  for (const LoopClosure& loop : m.loops) {
    EXPECT_GE(SurfaceDirections(m.submap_clouds[static_cast<std::size_t>(loop.to)],
                                options.mapper.weak_direction_ratio),
              options.mapper.loop_min_directions - 1)
        << loop.from << " -> " << loop.to;
    accepted += loop.accepted ? 1 : 0;
  }
  EXPECT_GT(accepted, 5);
}

// A loop frees the submaps back to its older end only when the graph misses it by more than
// loop_window_chi2_per_direction: with 0 every loop does, with infinity none, and the map is
// the same to a fraction of its error either way.
TEST_F(DiveMappingTest, OnlyLoopsThatCorrectTheGraphFreeItBackToTheirOlderEnd) {
  const fs::path log = Simulate(OutAndBackOverAPipe(), "pipe_loop.db");
  DiveMappingOptions options = Options();
  options.mapper.solve_window_submaps = 6;
  auto map_with = [&](double chi2_per_direction) {
    options.mapper.loop_window_chi2_per_direction = chi2_per_direction;
    return MapDive(DiveLogReader(log), options);
  };
  const DiveMapping every = map_with(0.0), some = map_with(0.5),
                    none = map_with(std::numeric_limits<double>::infinity());
  // How far a loop pulls the graph in its own information is at least its chi-square against
  // the prediction, whose information (that of the sum with the prediction's covariance) is the
  // smaller.
  int correcting = 0, accepted = 0;
  for (const LoopClosure& loop : some.loops) {
    EXPECT_GE(loop.correction_chi2, loop.chi2 * (1.0 - 1e-6) - 1e-9)
        << loop.from << " -> " << loop.to;
    accepted += loop.accepted ? 1 : 0;
    correcting += loop.accepted && loop.correction_chi2 > 0.5 * loop.constrained_directions;
  }
  std::printf("loops accepted %d, correcting %d; solves back to a loop %d / %d / %d\n", accepted,
              correcting, every.stats.loop_window_solves, some.stats.loop_window_solves,
              none.stats.loop_window_solves);
  EXPECT_GT(every.stats.loop_window_solves, 0);
  EXPECT_EQ(none.stats.loop_window_solves, 0);
  EXPECT_GT(some.stats.loop_window_solves, 0);
  EXPECT_LE(some.stats.loop_window_solves, correcting);
  EXPECT_LT(correcting, accepted);
  const double ate_every = AbsoluteTrajectoryError(every.slam, every.truth);
  const double ate_some = AbsoluteTrajectoryError(some.slam, some.truth);
  const double ate_none = AbsoluteTrajectoryError(none.slam, none.truth);
  std::printf("ATE %.2f / %.2f / %.2f mm\n", ate_every * 1e3, ate_some * 1e3, ate_none * 1e3);
  EXPECT_LT(std::abs(ate_some - ate_every), 0.05 * ate_every);
  EXPECT_LT(std::abs(ate_none - ate_every), 0.05 * ate_every);
}

// The loop dive of bench slam, seed 12: twice a loop closes on the newest scan and pulls it a
// couple of centimetres from its anchor, where nothing newer holds it yet, and the next scan's
// registration, right to a millimetre, was judged against a prediction that carried that offset
// (chi-square 25 and 40) and left to the navigation. Judged against the navigation's motion
// alone, every registration turned away is one further from the truth than the navigation.
TEST_F(DiveMappingTest, NoRightRegistrationIsTurnedAwayAfterALoopMovesTheScanBeforeIt) {
  scanner::sim::Scene scene = scanner::sim::LoadScene(fs::path(UWSCAN_SOURCE_DIR_FOR_TESTS) /
                                                      "data/scenes/inspection_loop.yaml");
  scene.seed = 12;
  const DiveMapping m = Map(Simulate(scene, "loop12.db"));
  const MapSummary s = Summarise(m);
  EXPECT_GT(s.loops_accepted, 30);
  EXPECT_EQ(s.registrations_missed.value_or(-1), 0);
  EXPECT_EQ(static_cast<int>(m.inconsistent_registrations.size()),
            m.stats.registrations_inconsistent);
}

}  // namespace
}  // namespace uwscan::mapping::test
