#include "perception/cloud/point_cloud.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

// The corners of a 0.3 x 0.2 x 0.1 m box among points inside it: the diameter is the box
// diagonal exactly, while the box of a rotated L-shape overstates its diameter.
TEST(Diameter, ExactBelowTheCapAndNeverAboveTheTruthBeyondIt) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  PointCloud box;
  box.origin = Eigen::Vector3d(1e5, -2e5, 30.0);  // far from the origin: offsets stay small
  for (int i = 0; i < 3000; ++i)
    box.points.push_back({0.3f * u(rng), 0.2f * u(rng), 0.1f * u(rng)});
  box.points.emplace_back(0.0f, 0.0f, 0.0f);
  box.points.emplace_back(0.3f, 0.2f, 0.1f);
  const double truth = std::sqrt(0.09 + 0.04 + 0.01);
  EXPECT_NEAR(Diameter(box), truth, 1e-6);
  const double capped = Diameter(box, 500);
  EXPECT_LE(capped, truth + 1e-6);
  EXPECT_GT(capped, 0.9 * truth);

  // A disc of radius 0.1 m: its diameter is 0.2 m, its bounding box diagonal 0.28 m.
  PointCloud disc;
  for (int i = 0; i < 360; ++i) {
    const float a = static_cast<float>(i) * 3.14159265f / 180.0f;
    disc.points.emplace_back(0.1f * std::cos(a), 0.1f * std::sin(a), 0.0f);
  }
  EXPECT_NEAR(Diameter(disc), 0.2, 1e-6);
  EXPECT_GT(BoundingBoxDiagonal(disc), 0.28);
  EXPECT_EQ(Diameter(PointCloud{}), 0.0);
}

// The mean of the points, in the cloud's frame (its origin added), also far from the frame's
// origin where the offsets are float; an empty cloud has none.
TEST(Centroid, IsTheMeanOfThePointsAndRefusesAnEmptyCloud) {
  PointCloud cloud;
  cloud.origin = Eigen::Vector3d(5000.0, -3000.0, 120.0);
  cloud.points = {{0.1f, 0.0f, 0.0f}, {-0.1f, 0.2f, 0.0f}, {0.3f, 0.1f, -0.6f}};
  const Eigen::Vector3d expected = cloud.origin + Eigen::Vector3d(0.3, 0.3, -0.6) / 3.0;
  EXPECT_LT((Centroid(cloud) - expected).norm(), 1e-7);
  EXPECT_THROW(Centroid(PointCloud{}), Error);
}

}  // namespace
}  // namespace uwscan::perception
