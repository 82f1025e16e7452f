// Frame by frame, the incremental reconstruction equals Reconstruct on the same log.
#include "mapping/reconstruction/incremental_reconstruction.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "mapping/log/dive_simulation.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"

namespace uwscan::mapping {
namespace {

TEST(IncrementalReconstruction, SamePointsTruthAndFramesAsReconstruct) {
  const scanner::sim::Scene scene = scanner::sim::LoadScene(
      std::filesystem::path(UWSCAN_SOURCE_DIR_FOR_TESTS) / "data/scenes/default.yaml");
  const scanner::sim::Simulator simulator(scene);
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("uwscan_incremental_test_" + std::to_string(::getpid()) + ".db");
  std::filesystem::remove(path);
  SimulateDive(simulator, "", path, DiveSimulationOptions{});
  const DiveLogReader log(path);
  const Reconstruction whole = Reconstruct(log, {});

  IncrementalReconstructor incremental(log, {});
  std::vector<Eigen::Vector3d> points, truth;
  std::vector<std::int64_t> frame_of_point;
  std::int64_t polls = 0;
  // Small polls: the result must not depend on how the frames were grouped.
  for (std::vector<ReconstructedFrame> frames; !(frames = incremental.Poll(7)).empty(); ++polls) {
    for (const ReconstructedFrame& f : frames) {
      ASSERT_EQ(f.truth.size(), f.points.size());
      ASSERT_EQ(f.object_ids.size(), f.points.size());
      points.insert(points.end(), f.points.begin(), f.points.end());
      truth.insert(truth.end(), f.truth.begin(), f.truth.end());
      frame_of_point.insert(frame_of_point.end(), f.points.size(), f.index);
    }
  }
  EXPECT_EQ(incremental.frames_done(), whole.frames);
  EXPECT_EQ(incremental.world_frame(), whole.world_frame);
  EXPECT_GT(polls, 10);
  ASSERT_EQ(points.size(), whole.points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    ASSERT_EQ(points[i], whole.points[i]) << i;
    ASSERT_EQ(frame_of_point[i], whole.frame_of_point[i]) << i;
    ASSERT_TRUE(truth[i] == whole.truth[i] || (truth[i].hasNaN() && whole.truth[i].hasNaN())) << i;
  }
  EXPECT_TRUE(incremental.Poll().empty());
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace uwscan::mapping
