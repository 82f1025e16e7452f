#include "mapping/reconstruction/scan_file.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <string>

#include "mapping/log/dive_log_test_support.hpp"
#include "mapping/log/dive_simulation.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"

namespace uwscan::mapping::test {
namespace {

class ScanFileTest : public DiveLogTest {
 protected:
  // The short inspection dive's first four sweeps, the vehicle moving 0.2 m/s, navigation exact.
  fs::path MovingDive() {
    scanner::sim::Scene scene = scanner::sim::LoadScene(fs::path(UWSCAN_SOURCE_DIR_FOR_TESTS) /
                                                        "data/scenes/inspection_short.yaml");
    scene.scanner.sweeps = 4;
    scene.effects.navigation_drift.on = false;
    scene.effects.peak_noise.on = false;
    const fs::path path = dir_ / "moving.db";
    const scanner::sim::Simulator simulator(scene);
    DiveSimulationOptions options;
    options.threads = 2;
    SimulateDive(simulator, "", path, options);
    return path;
  }
};

TEST_F(ScanFileTest, ACloudFileSaysWhichRowEachFinitePointCameFrom) {
  const fs::path path = dir_ / "holes.xyz";
  {
    std::ofstream out(path);
    out << "0 0 1\nnan 0 1\n0.1 0 1\n0 inf 1\n0.2 0 1\n";
  }
  const ScanFile scan = ReadScanFile(path);
  ASSERT_EQ(scan.cloud.size(), 3u);
  EXPECT_EQ(scan.rows, (std::vector<std::size_t>{0, 2, 4}));
  EXPECT_EQ(scan.rows_in_file, 5u);
  EXPECT_NEAR(scan.cloud.Point(1).x(), 0.1, 1e-6);

  ReconstructionOptions options;
  options.sweep = 0;
  EXPECT_NE(MessageOf([&] { ReadScanFile(path, options); }).find("this is a cloud file"),
            std::string::npos);
}

// A sweep taken while the vehicle moves 10 cm: each frame placed with the navigation, the
// points in the camera frame at the sweep's middle lie on the true surfaces there; stacked as
// if the scanner had stood still (what a cloud in the camera frame of each frame gives), they
// would be smeared by the motion.
TEST_F(ScanFileTest, ASweepOfAMovingDiveIsPlacedWithItsNavigation) {
  const fs::path path = MovingDive();
  EXPECT_NE(MessageOf([&] {
              ReadScanFile(path);
            }).find("holds 4 sweeps, 0 to 3; recognition takes one: choose it with --sweep"),
            std::string::npos)
      << MessageOf([&] { ReadScanFile(path); });
  ReconstructionOptions options;
  options.sweep = 7;
  EXPECT_NE(MessageOf([&] {
              ReadScanFile(path, options);
            }).find("has no sweep 7 (it holds 4 sweeps, 0 to 3)"),
            std::string::npos);

  options.sweep = 2;
  const ScanFile scan = ReadScanFile(path, options);
  const DiveLogReader log(path);
  options.use_navigation = true;
  options.relative_to_middle = true;
  const Reconstruction placed = Reconstruct(log, options);
  ASSERT_EQ(placed.truth.size(), scan.cloud.size());
  ASSERT_GT(scan.cloud.size(), 10000u);
  options.use_navigation = false;  // each frame in its own camera frame, as if at rest
  const Reconstruction at_rest = Reconstruct(log, options);
  ASSERT_EQ(at_rest.points.size(), scan.cloud.size());
  double worst_placed_m = 0.0, worst_at_rest_m = 0.0;
  for (std::size_t i = 0; i < scan.cloud.size(); ++i) {
    if (!placed.truth[i].allFinite()) continue;
    EXPECT_EQ(placed.frame_of_point[i], at_rest.frame_of_point[i]);
    worst_placed_m = std::max(worst_placed_m, (scan.cloud.Point(i) - placed.truth[i]).norm());
    worst_at_rest_m = std::max(worst_at_rest_m, (at_rest.points[i] - placed.truth[i]).norm());
  }
  EXPECT_LT(worst_placed_m, 1e-4);
  EXPECT_GT(worst_at_rest_m, 0.02);
  for (std::int64_t frame : placed.frame_of_point) EXPECT_EQ(log.ReadFrame(frame).sweep, 2);
}

}  // namespace
}  // namespace uwscan::mapping::test
