// Online inspection without a camera: frames of a simulated dive pushed as a camera would.
#include "mapping/inspection/live_inspection.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <set>
#include <thread>
#include <unordered_map>

#include "mapping/log/dive_simulation.hpp"
#include "scanner/common/error.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"

namespace uwscan::mapping {
namespace {

namespace fs = std::filesystem;

double Now() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// Nearest-point distances through a hash grid of `cell_m` cells (the 27 around a point).
class NearestPoints {
 public:
  NearestPoints(const std::vector<Eigen::Vector3d>& points, double cell_m)
      : points_(points), cell_m_(cell_m) {
    for (std::size_t i = 0; i < points.size(); ++i) grid_.emplace(Key(points[i], 0, 0, 0), i);
  }
  // Distance to the nearest point, or cell_m when none lies within the neighbouring cells.
  double Distance(const Eigen::Vector3d& p) const {
    double best = cell_m_;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          auto [first, last] = grid_.equal_range(Key(p, dx, dy, dz));
          for (auto it = first; it != last; ++it)
            best = std::min(best, (points_[it->second] - p).norm());
        }
    return best;
  }

 private:
  std::int64_t Key(const Eigen::Vector3d& p, int dx, int dy, int dz) const {
    const auto i = static_cast<std::int64_t>(std::floor(p.x() / cell_m_)) + dx;
    const auto j = static_cast<std::int64_t>(std::floor(p.y() / cell_m_)) + dy;
    const auto k = static_cast<std::int64_t>(std::floor(p.z() / cell_m_)) + dz;
    return (i * 73856093) ^ (j * 19349663) ^ (k * 83492791);
  }
  const std::vector<Eigen::Vector3d>& points_;
  double cell_m_;
  std::unordered_multimap<std::int64_t, std::size_t> grid_;
};

// The default scene (static scanner, world = camera frame, exact peaks), simulated once.
class LiveInspectionTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("uwscan_live_inspection_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    const scanner::sim::Simulator simulator(scanner::sim::LoadScene(
        fs::path(UWSCAN_SOURCE_DIR_FOR_TESTS) / "data/scenes/default.yaml"));
    DiveSimulationOptions options;
    options.threads = 2;
    SimulateDive(simulator, "", dir_ / "sim.db", options);
    const DiveLogReader log(dir_ / "sim.db");
    header_ = new DiveLogHeader(log.header());
    frames_ = new std::vector<FrameRecord>();
    truth_ = new std::vector<std::vector<Eigen::Vector3d>>();
    log.ForEachFrame(
        [](const FrameRecord& f, const GroundTruthRecord* t) {
          frames_->push_back(f);
          truth_->push_back(t->points_W);
        },
        true);
  }
  static void TearDownTestSuite() {
    delete header_;
    delete frames_;
    delete truth_;
    fs::remove_all(dir_);
  }

  static InspectionOptions Options() {
    InspectionOptions o;
    o.mapper.threads = 1;
    o.map_voxel_m = 0.002;
    o.table_cache = dir_ / "tables";
    return o;
  }
  // Frame k of the dive shown again and again, as the fake camera does: pass p moves time and
  // sweep on.
  static InspectionFrame Frame(std::int64_t k) {
    const std::int64_t n = static_cast<std::int64_t>(frames_->size());
    const FrameRecord& f = (*frames_)[static_cast<std::size_t>(k % n)];
    InspectionFrame out;
    out.record = f;
    out.record.time_s += static_cast<double>(k / n) * n / 339.0;
    out.record.sweep += static_cast<int>(k / n);
    out.receive_time_s = Now();
    return out;
  }
  static const std::vector<Eigen::Vector3d>& Truth(std::int64_t k) {
    return (*truth_)[static_cast<std::size_t>(k % static_cast<std::int64_t>(truth_->size()))];
  }

  static inline fs::path dir_;
  static inline DiveLogHeader* header_ = nullptr;
  static inline std::vector<FrameRecord>* frames_ = nullptr;
  static inline std::vector<std::vector<Eigen::Vector3d>>* truth_ = nullptr;
};

void ExpectBalanced(const InspectionStatistics& s) {
  EXPECT_EQ(s.frames_received, s.frames_mapped + s.frames_skipped + s.frames_out_of_order +
                                   s.frames_without_navigation + s.frames_waiting);
}

// A mapper that keeps up (a queue that never fills): every frame logged and mapped, each
// frame's points on the simulator's truth, the map on the truth within its voxel.
TEST_F(LiveInspectionTest, EveryFrameIsLoggedAndMappedOntoTheTruth) {
  InspectionOptions options = Options();
  options.live_queue_frames = 100000;
  const std::int64_t n = 2 * static_cast<std::int64_t>(frames_->size());
  double worst_frame_m = 0.0;
  std::int64_t frames_checked = 0;
  const fs::path log = dir_ / "every.db";
  LiveInspection inspection(*header_, log, Eigen::Isometry3d::Identity(), NavigationNoise{},
                            options, [&](const MappedFrame& f) {
                              const NearestPoints truth(Truth(f.index), 0.01);
                              for (const Eigen::Vector3d& p : f.points_W)
                                worst_frame_m = std::max(worst_frame_m, truth.Distance(p));
                              ++frames_checked;
                            });
  for (std::int64_t k = 0; k < n; ++k) inspection.Push(Frame(k));
  const InspectionResult result = inspection.Finish();
  const InspectionStatistics& s = result.statistics;
  EXPECT_EQ(s.frames_received, n);
  EXPECT_EQ(s.frames_logged, n);
  EXPECT_EQ(s.frames_mapped, n);
  EXPECT_EQ(s.frames_skipped, 0);
  EXPECT_EQ(s.frames_waiting, 0);
  EXPECT_EQ(frames_checked, n);
  ExpectBalanced(s);
  EXPECT_LT(worst_frame_m, 1e-4) << "ray-cone triangulation is within 0.05 mm of exact";

  const DiveLogReader reader(log);
  ASSERT_EQ(reader.frame_count(), n);
  for (std::int64_t k : {std::int64_t{0}, n / 2 + 3, n - 1}) {
    const FrameRecord f = reader.ReadFrame(k);
    EXPECT_EQ(f.peaks_px, Frame(k).record.peaks_px) << k;
    EXPECT_EQ(f.time_s, Frame(k).record.time_s) << k;
  }

  std::vector<Eigen::Vector3d> all_truth;
  for (const auto& t : *truth_) {
    for (const Eigen::Vector3d& p : t) {
      if (p.allFinite()) all_truth.push_back(p);
    }
  }
  const NearestPoints truth(all_truth, 0.01);
  ASSERT_GT(result.map.size(), 10000u);
  double worst_m = 0.0, sum_m = 0.0;
  for (std::size_t i = 0; i < result.map.size(); ++i) {
    const double d = truth.Distance(result.map.Point(i));
    worst_m = std::max(worst_m, d);
    sum_m += d;
  }
  // A voxel's centroid lies within the voxel of the points it averages.
  EXPECT_LT(worst_m, std::sqrt(3.0) * options.map_voxel_m + 1e-4);
  EXPECT_LT(sum_m / static_cast<double>(result.map.size()), 0.5e-3);
  ASSERT_EQ(result.slam.size(), 2u);  // two sweeps: a submap each
  // The fixed scanner stays put: the two submaps are registered to each other, to within a
  // small fraction of the points' spacing.
  for (const TimedPose& pose : result.slam) EXPECT_LT(pose.T_W_V.translation().norm(), 1e-4);
}

// A mapper held up on the first frame: the live queue keeps the newest frames and skips the
// rest; the log still gets every one.
TEST_F(LiveInspectionTest, WhenTheMapperIsBehindTheOldestFramesAreSkippedNotLogged) {
  InspectionOptions options = Options();
  options.live_queue_frames = 4;
  std::mutex mutex;
  std::condition_variable changed;
  bool first_placed = false, release = false;
  std::set<std::int64_t> mapped;
  LiveInspection inspection(*header_, dir_ / "skip.db", Eigen::Isometry3d::Identity(),
                            NavigationNoise{}, options, [&](const MappedFrame& f) {
                              std::unique_lock<std::mutex> lock(mutex);
                              mapped.insert(f.index);
                              first_placed = true;
                              changed.notify_all();
                              changed.wait(lock, [&] { return release; });
                            });
  inspection.Push(Frame(0));
  {
    std::unique_lock<std::mutex> lock(mutex);
    changed.wait(lock, [&] { return first_placed; });
  }
  const std::int64_t n = 60;
  for (std::int64_t k = 1; k < n; ++k) inspection.Push(Frame(k));
  const InspectionStatistics during = inspection.statistics();
  EXPECT_EQ(during.frames_skipped, n - 1 - 4);
  EXPECT_EQ(during.frames_waiting, 1 + 4);  // the one being placed and the queue
  ExpectBalanced(during);
  {
    std::lock_guard<std::mutex> lock(mutex);
    release = true;
  }
  changed.notify_all();
  const InspectionResult result = inspection.Finish();
  EXPECT_EQ(result.statistics.frames_received, n);
  EXPECT_EQ(result.statistics.frames_mapped, 5);
  EXPECT_EQ(result.statistics.frames_skipped, n - 5);
  ExpectBalanced(result.statistics);
  EXPECT_EQ(mapped, (std::set<std::int64_t>{0, n - 4, n - 3, n - 2, n - 1}));
  EXPECT_EQ(DiveLogReader(dir_ / "skip.db").frame_count(), n);
  EXPECT_EQ(result.statistics.frames_logged, n);
}

TEST_F(LiveInspectionTest, LatencyIsMeasuredFromCaptureAndFromReceive) {
  InspectionOptions options = Options();
  options.live_queue_frames = 1000;
  LiveInspection inspection(*header_, "", Eigen::Isometry3d::Identity(), NavigationNoise{},
                            options);
  const std::int64_t n = 30;
  for (std::int64_t k = 0; k < n; ++k) {
    InspectionFrame f = Frame(k);
    f.receive_time_s = Now();
    if (k % 2 == 0) f.capture_time_s = f.receive_time_s - 0.010;  // exposed 10 ms before it came
    inspection.Push(std::move(f));
  }
  const InspectionStatistics s = inspection.Finish().statistics;
  EXPECT_EQ(s.frames_logged, 0);  // no log
  EXPECT_EQ(s.receive_to_map.frames, n);
  EXPECT_EQ(s.capture_to_map.frames, n / 2);
  EXPECT_GT(s.receive_to_map.median_s, 0.0);
  EXPECT_LT(s.receive_to_map.max_s, 5.0);
  EXPECT_GE(s.capture_to_map.median_s, 0.010);
  EXPECT_LE(s.receive_to_map.median_s, s.receive_to_map.p95_s);
  EXPECT_LE(s.receive_to_map.p95_s, s.receive_to_map.max_s);
}

// A restarted camera starts its clock and sweeps again: a fixed scanner maps on.
TEST_F(LiveInspectionTest, AFixedScannerMapsOnWhenTheCameraClockRestarts) {
  InspectionOptions options = Options();
  options.live_queue_frames = 100000;
  LiveInspection inspection(*header_, "", Eigen::Isometry3d::Identity(), NavigationNoise{},
                            options);
  const std::int64_t n = static_cast<std::int64_t>(frames_->size());
  for (std::int64_t k = 0; k < n + 10; ++k) inspection.Push(Frame(k));
  for (std::int64_t k = 0; k < 20; ++k) inspection.Push(Frame(k));  // time and sweep from 0 again
  const InspectionStatistics s = inspection.Finish().statistics;
  EXPECT_EQ(s.clock_restarts, 1);
  EXPECT_EQ(s.frames_mapped, n + 30);
  ExpectBalanced(s);
}

// With navigation, frames wait in the mapper until it covers their time; an older frame than
// one already mapped is counted, not mapped.
TEST_F(LiveInspectionTest, WithNavigationFramesWaitForItAndOldOnesAreRefused) {
  InspectionOptions options = Options();
  options.fixed_scanner = false;
  options.live_queue_frames = 100000;
  LiveInspection inspection(*header_, "", Eigen::Isometry3d::Identity(), NavigationNoise{},
                            options);
  for (std::int64_t k = 0; k < 20; ++k) inspection.Push(Frame(k));
  InspectionFrame old = Frame(3);
  inspection.Push(std::move(old));
  for (int i = 0; i < 200 && inspection.statistics().frames_out_of_order == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  InspectionStatistics s = inspection.statistics();
  EXPECT_EQ(s.frames_mapped, 0);
  EXPECT_EQ(s.frames_out_of_order, 1);
  EXPECT_EQ(s.frames_waiting, 20);
  ExpectBalanced(s);
  inspection.AddNavigation({0.0, Eigen::Isometry3d::Identity()});
  inspection.AddNavigation({1.0, Eigen::Isometry3d::Identity()});
  s = inspection.Finish().statistics;
  EXPECT_EQ(s.frames_mapped, 20);
  EXPECT_EQ(s.frames_waiting, 0);
  ExpectBalanced(s);
}

// A navigation dropout longer than MapperOptions::max_navigation_gap_s: the frames inside it are
// logged and counted, not placed with a pose bridged across it.
TEST_F(LiveInspectionTest, FramesInANavigationDropoutAreCountedNotMapped) {
  InspectionOptions options = Options();
  options.fixed_scanner = false;
  options.live_queue_frames = 100000;
  LiveInspection inspection(*header_, "", Eigen::Isometry3d::Identity(), NavigationNoise{},
                            options);
  const double last_sample_s = Frame(6).record.time_s;
  std::int64_t after = 0;
  for (std::int64_t k = 0; k < 20; ++k) {
    InspectionFrame f = Frame(k);
    after += f.record.time_s > last_sample_s ? 1 : 0;
    inspection.Push(std::move(f));
  }
  ASSERT_GT(after, 5);
  inspection.AddNavigation({0.0, Eigen::Isometry3d::Identity()});
  inspection.AddNavigation({last_sample_s, Eigen::Isometry3d::Identity()});
  inspection.AddNavigation({last_sample_s + 2.0, Eigen::Isometry3d::Identity()});
  const InspectionStatistics s = inspection.Finish().statistics;
  EXPECT_EQ(s.frames_without_navigation, after);
  EXPECT_EQ(s.frames_mapped, 20 - after);
  EXPECT_EQ(s.frames_waiting, 0);
  ExpectBalanced(s);
}

// Navigation that stops: the frames after it do not pile up in the mapper (memory bounded by
// the frames of max_navigation_gap_s + navigation_latency_s); they are left out and counted as
// they would be at the end anyway, and every one is logged.
TEST_F(LiveInspectionTest, FramesAfterTheNavigationStoppedAreLeftOutWithoutPilingUp) {
  InspectionOptions options = Options();
  options.fixed_scanner = false;
  options.live_queue_frames = 100000;
  const fs::path log = dir_ / "stopped.db";
  LiveInspection inspection(*header_, log, Eigen::Isometry3d::Identity(), NavigationNoise{},
                            options);
  const double stop_s = 0.5;
  inspection.AddNavigation({0.0, Eigen::Isometry3d::Identity()});
  inspection.AddNavigation({stop_s, Eigen::Isometry3d::Identity()});
  const std::int64_t n = 4000;  // 11.8 s at 339 frames/s
  std::int64_t before_stop = 0;
  for (std::int64_t k = 0; k < n; ++k) {
    InspectionFrame f = Frame(k);
    before_stop += f.record.time_s <= stop_s ? 1 : 0;
    inspection.Push(std::move(f));
  }
  // The frames of the last 2 s (gap + latency) may still wait; all older ones are decided.
  const MapperOptions mapper;
  const double window_s = mapper.max_navigation_gap_s + mapper.navigation_latency_s;
  const std::int64_t last_window = static_cast<std::int64_t>(std::ceil(window_s * 339.0)) + 2;
  InspectionStatistics s = inspection.statistics();
  // Waits for the mapping thread (long enough for the sanitized build, which maps ~10x slower).
  for (int i = 0; i < 30000 && s.frames_waiting > last_window; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    s = inspection.statistics();
  }
  EXPECT_LE(s.frames_waiting, last_window);
  EXPECT_GE(s.frames_without_navigation, n - before_stop - last_window);
  ExpectBalanced(s);
  s = inspection.Finish().statistics;
  EXPECT_EQ(s.frames_mapped, before_stop);
  EXPECT_EQ(s.frames_without_navigation, n - before_stop);
  EXPECT_EQ(s.frames_logged, n);
  EXPECT_EQ(DiveLogReader(log).ReadNavigation().size(), 2u);  // the navigation is logged too
  ExpectBalanced(s);
}

TEST_F(LiveInspectionTest, FramesWithoutAnyNavigationFailClearly) {
  InspectionOptions options = Options();
  options.fixed_scanner = false;
  LiveInspection inspection(*header_, "", Eigen::Isometry3d::Identity(), NavigationNoise{},
                            options);
  inspection.Push(Frame(0));
  EXPECT_THROW(inspection.Finish(), Error);
}

TEST(InspectionOptions, CheckNamesTheField) {
  InspectionOptions o;
  o.live_queue_frames = 0;
  EXPECT_THROW(o.Check(), Error);
  o = InspectionOptions{};
  o.map_voxel_m = 0.0;
  try {
    o.Check();
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("map_voxel_m"), std::string::npos);
  }
  o = InspectionOptions{};
  o.log_queue_bytes = 0;
  EXPECT_THROW(o.Check(), Error);
  EXPECT_NO_THROW(InspectionOptions{}.Check());
}

}  // namespace
}  // namespace uwscan::mapping
