// The SLAM bench's walk scale: the scene's random walks scaled, nothing else changed.
#include "bench/slam/slam_benchmark.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/sim/scene.hpp"

namespace uwscan::bench {
namespace {

const std::filesystem::path kScenes =
    std::filesystem::path(UWSCAN_SOURCE_DIR_FOR_TESTS) / "data" / "scenes";

std::string ReadScene(const std::string& name) {
  std::ifstream in(kScenes / name, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(SlamBenchWalkScale, ScalesTheRandomWalksAndNothingElse) {
  const std::filesystem::path path = kScenes / "inspection_loop.yaml";
  const std::string text = ReadScene("inspection_loop.yaml");
  const scanner::sim::Scene original = scanner::sim::ParseScene(text, path.string(), kScenes);
  const scanner::sim::Scene scaled =
      scanner::sim::ParseScene(SceneWithWalkScale(text, 0.1, path), path.string(), kScenes);
  const auto& before = original.effects.navigation_drift;
  const auto& after = scaled.effects.navigation_drift;
  ASSERT_TRUE(before.on && after.on);
  EXPECT_NEAR(after.position_walk_m_per_sqrt_s, 0.1 * before.position_walk_m_per_sqrt_s, 1e-15);
  EXPECT_NEAR(after.yaw_walk_rad_per_sqrt_s, 0.1 * before.yaw_walk_rad_per_sqrt_s, 1e-15);
  EXPECT_EQ(after.speed_scale_sigma, before.speed_scale_sigma);
  EXPECT_EQ(after.heading_bias_sigma_rad, before.heading_bias_sigma_rad);
  EXPECT_EQ(after.depth_sigma_m, before.depth_sigma_m);
  EXPECT_EQ(after.roll_pitch_sigma_rad, before.roll_pitch_sigma_rad);
  EXPECT_EQ(scaled.seed, original.seed);
  EXPECT_EQ(scaled.objects.size(), original.objects.size());
  EXPECT_EQ(scaled.trajectory.poses.size(), original.trajectory.poses.size());
  EXPECT_EQ(SceneWithWalkScale(text, 1.0, path), text);
}

TEST(SlamBenchWalkScale, ASceneWithoutNavigationDriftIsRefusedByName) {
  const std::filesystem::path path = kScenes / "default.yaml";
  try {
    SceneWithWalkScale(ReadScene("default.yaml"), 0.5, path);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("default.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("navigation_drift"), std::string::npos) << e.what();
  }
  EXPECT_THROW(SceneWithWalkScale("effects: [unclosed", 0.5, path), Error);
}

}  // namespace
}  // namespace uwscan::bench
