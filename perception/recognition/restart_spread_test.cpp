#include "perception/recognition/restart_spread.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

// Points on a grid over the squares of `faces` (each a corner, two edges and a normal), 1 cm
// apart, shifted by `offset` of a spacing so that source and target points do not coincide.
PointCloud Faces(const std::vector<std::array<Eigen::Vector3d, 3>>& faces, double offset) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3f> normals;
  for (const auto& [corner, edge, normal] : faces) {
    const Eigen::Vector3d other = normal.cross(edge);
    for (int i = 0; i < 20; ++i) {
      for (int k = 0; k < 20; ++k) {
        points.push_back(corner + 0.01 * (i + offset) * edge + 0.01 * (k + offset) * other);
        normals.push_back(normal.cast<float>());
      }
    }
  }
  PointCloud cloud = MakeCloud(points);
  cloud.normals = normals;
  return cloud;
}

IcpOptions PointToPlane() {
  IcpOptions icp;
  icp.method = IcpMethod::kPointToPlane;
  icp.max_correspondence_distance_m = {0.02};
  icp.translation_tolerance_m = 1e-7;
  icp.rotation_tolerance_rad = 1e-7;
  icp.relative_rmse_tolerance = 1e-9;
  icp.max_iterations = icp.max_iterations_per_stage = 100;
  return icp;
}

// A covariance whose scaled eigenvectors are the six axes: rotations about x, y, z, slides.
Matrix6d AxesCovariance() {
  Eigen::Matrix<double, 6, 1> d;
  d << 1e-6, 2e-6, 3e-6, 4e-8, 5e-8, 6e-8;
  return d.asDiagonal();
}

const std::vector<std::array<Eigen::Vector3d, 3>> kPlane = {
    {Eigen::Vector3d(-0.1, -0.1, 0.0), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ()}};

// A flat patch: point-to-plane pairs do not hold the slides in its plane nor the turn about its
// normal, which its information (none there) would say and a covariance claiming all six pinned
// would not. The restarts stay where they start along those three and come back along the rest.
TEST(RestartSpread, APlaneLeavesItsSlidesAndTurnWhereTheyStart) {
  const PointCloud target = Faces(kPlane, 0.0), source = Faces(kPlane, 0.5);
  const IcpTarget prepared(target);
  const Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  const double radius = 0.1, step = 0.002;
  const Matrix6d spread = RestartSpread(source, prepared, Eigen::Isometry3d::Identity(),
                                        PointToPlane(), AxesCovariance(), centre, radius, step, 2);
  Matrix6d scale = Matrix6d::Identity();
  scale.topLeftCorner<3, 3>() *= radius;
  const Matrix6d in_metres = scale * spread * scale;
  EXPECT_NEAR(in_metres(2, 2), step * step, 1e-3 * step * step);  // turn about the normal
  EXPECT_NEAR(in_metres(3, 3), step * step, 1e-3 * step * step);  // slide along x
  EXPECT_NEAR(in_metres(4, 4), step * step, 1e-3 * step * step);  // slide along y
  for (int k : {0, 1, 5}) EXPECT_LT(in_metres(k, k), 1e-6 * step * step) << k;  // tilts, lift
  // The same bits on one thread.
  EXPECT_TRUE(spread == RestartSpread(source, prepared, Eigen::Isometry3d::Identity(),
                                      PointToPlane(), AxesCovariance(), centre, radius, step, 1));
}

// Three faces of a box pin every direction: every restart comes back to the answer. (The scan is
// the model's own points: shifted by half a spacing, the points past the edges make other minima.)
TEST(RestartSpread, ABoxCornerBringsEveryRestartBack) {
  const std::vector<std::array<Eigen::Vector3d, 3>> corner = {
      {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ()},
      {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY()},
      {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitX()}};
  const PointCloud target = Faces(corner, 0.0), source = Faces(corner, 0.0);
  const IcpTarget prepared(target);
  const Eigen::Vector3d centre(0.05, 0.05, 0.05);
  const double radius = 0.1, step = 0.002;
  const Matrix6d spread = RestartSpread(source, prepared, Eigen::Isometry3d::Identity(),
                                        PointToPlane(), AxesCovariance(), centre, radius, step, 2);
  Matrix6d scale = Matrix6d::Identity();
  scale.topLeftCorner<3, 3>() *= radius;
  EXPECT_LT((scale * spread * scale).norm(), 1e-4 * step * step);
}

// Directions the covariance leaves free (none of its variance) are neither restarted along nor
// counted: a covariance with nothing pinned adds nothing.
TEST(RestartSpread, FreeDirectionsAreLeftOut) {
  const PointCloud target = Faces(kPlane, 0.0), source = Faces(kPlane, 0.5);
  const IcpTarget prepared(target);
  Matrix6d covariance = AxesCovariance();
  for (int k : {2, 3, 4}) covariance(k, k) = 0.0;  // the plane's own free directions
  const Matrix6d spread =
      RestartSpread(source, prepared, Eigen::Isometry3d::Identity(), PointToPlane(), covariance,
                    Eigen::Vector3d::Zero(), 0.1, 0.002, 2);
  EXPECT_LT(spread.norm(), 1e-12);
  EXPECT_TRUE(RestartSpread(source, prepared, Eigen::Isometry3d::Identity(), PointToPlane(),
                            Matrix6d::Zero(), Eigen::Vector3d::Zero(), 0.1, 0.002, 2)
                  .isZero());
}

TEST(RestartSpread, RefusesBadScalars) {
  const PointCloud target = Faces(kPlane, 0.0);
  const IcpTarget prepared(target);
  const auto run = [&](double radius, double step) {
    return RestartSpread(target, prepared, Eigen::Isometry3d::Identity(), PointToPlane(),
                         AxesCovariance(), Eigen::Vector3d::Zero(), radius, step, 1);
  };
  EXPECT_THROW(run(0.0, 0.002), Error);
  EXPECT_THROW(run(0.1, 0.0), Error);
  EXPECT_THROW(run(0.1, std::numeric_limits<double>::quiet_NaN()), Error);
}

}  // namespace
}  // namespace uwscan::perception
