#include "mapping/slam/registration_information.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

constexpr double kRatio = 0.02;  // MapperOptions::weak_direction_ratio's default

struct Surface {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;
  void Add(const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
    points.push_back(p);
    normals.push_back(n.normalized());
  }
};

// A 1 m square of seabed at z = 0, every centimetre, its normal up (-z: NED).
void AddSeabed(Surface* s) {
  for (int i = 0; i < 100; ++i) {
    for (int j = 0; j < 100; ++j) s->Add({0.01 * i - 0.5, 0.01 * j - 0.5, 0.0}, {0.0, 0.0, -1.0});
  }
}

// The upper half of a pipe of 10 cm radius along x, lying on the seabed, its ends out of view.
void AddPipe(Surface* s) {
  for (int i = 0; i < 100; ++i) {
    for (int a = 0; a <= 31; ++a) {
      const double angle = std::numbers::pi * a / 31.0;
      const Eigen::Vector3d radial{0.0, std::cos(angle), -std::sin(angle)};
      s->Add(Eigen::Vector3d(0.01 * i - 0.5, 0.0, -0.1) + 0.1 * radial, radial);
    }
  }
}

// A flange's face across the pipe at x = 0.3: a ring from 10 to 20 cm, facing +x.
void AddFlangeFace(Surface* s) {
  for (double y = -0.2; y <= 0.2; y += 0.01) {
    for (double z = -0.3; z <= 0.1; z += 0.01) {
      const double r = std::hypot(y, z + 0.1);
      if (r >= 0.1 && r <= 0.2) s->Add({0.3, y, z}, {1.0, 0.0, 0.0});
    }
  }
}

perception::PointCloud Cloud(const Surface& s,
                             const Eigen::Isometry3d& T = Eigen::Isometry3d::Identity()) {
  std::vector<Eigen::Vector3d> moved;
  for (const Eigen::Vector3d& p : s.points) moved.push_back(T * p);
  perception::PointCloud cloud = perception::MakeCloud(moved);
  for (const Eigen::Vector3d& n : s.normals)
    cloud.normals.push_back((T.linear() * n).cast<float>());
  return cloud;
}

TEST(SurfaceDirections, ABareSeabedPinsDepthRollAndPitch) {
  Surface s;
  AddSeabed(&s);
  EXPECT_EQ(SurfaceDirections(Cloud(s), kRatio), 3);
}

TEST(SurfaceDirections, APipeOnTheSeabedLeavesOnlyTheSlideAlongItFree) {
  Surface s;
  AddSeabed(&s);
  AddPipe(&s);
  EXPECT_EQ(SurfaceDirections(Cloud(s), kRatio), 5);
}

TEST(SurfaceDirections, AFlangeOnThePipePinsTheSlideToo) {
  Surface s;
  AddSeabed(&s);
  AddPipe(&s);
  AddFlangeFace(&s);
  EXPECT_EQ(SurfaceDirections(Cloud(s), kRatio), 6);
}

TEST(SurfaceDirections, DoNotDependOnWhereTheCloudIsOrHowItIsTurned) {
  Surface s;
  AddSeabed(&s);
  AddPipe(&s);
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
  far.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).matrix();
  far.translation() = Eigen::Vector3d(2500.0, -1300.0, 80.0);
  EXPECT_EQ(SurfaceDirections(Cloud(s, far), kRatio), 5);
  AddFlangeFace(&s);
  EXPECT_EQ(SurfaceDirections(Cloud(s, far), kRatio), 6);
}

TEST(SurfaceDirections, AnEmptyCloudPinsNothingAndACloudWithoutNormalsIsRefused) {
  EXPECT_EQ(SurfaceDirections(perception::PointCloud{}, kRatio), 0);
  Surface s;
  AddSeabed(&s);
  perception::PointCloud bare = Cloud(s);
  bare.normals.clear();
  EXPECT_THROW(SurfaceDirections(bare, kRatio), Error);
}

}  // namespace
}  // namespace uwscan::mapping
