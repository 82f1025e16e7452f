#include "ros/conversions/static_transforms.hpp"

#include <gtest/gtest.h>

#include <random>

#include "scanner/common/random_draws.hpp"

namespace uwscan::ros {
namespace {

Eigen::Isometry3d RandomPose(std::mt19937& rng) {
  std::normal_distribution<double> d(0.0, 1.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = DrawRotation(rng).toRotationMatrix();
  T.translation() = DrawVector3(d, rng);
  return T;
}

TEST(StaticTransforms, ComposesAChainInEitherDirection) {
  std::mt19937 rng(3);
  const Eigen::Isometry3d T_base_mast = RandomPose(rng);
  const Eigen::Isometry3d T_mast_camera = RandomPose(rng);
  const Eigen::Isometry3d T_base_dvl = RandomPose(rng);
  StaticTransforms statics;
  statics.Add({{0.0, "base_link"}, "mast", T_base_mast});
  statics.Add({{0.0, "mast"}, "camera", T_mast_camera});
  statics.Add({{0.0, "base_link"}, "dvl", T_base_dvl});
  const std::optional<Eigen::Isometry3d> T_base_camera = statics.Find("base_link", "camera");
  ASSERT_TRUE(T_base_camera);
  EXPECT_TRUE(T_base_camera->isApprox(T_base_mast * T_mast_camera, 1e-12));
  const std::optional<Eigen::Isometry3d> T_dvl_camera = statics.Find("dvl", "camera");
  ASSERT_TRUE(T_dvl_camera);
  EXPECT_TRUE(T_dvl_camera->isApprox(T_base_dvl.inverse() * T_base_mast * T_mast_camera, 1e-12));
  EXPECT_FALSE(statics.Find("base_link", "sonar"));
  EXPECT_TRUE(statics.Find("camera", "camera")->isApprox(Eigen::Isometry3d::Identity()));
}

}  // namespace
}  // namespace uwscan::ros
