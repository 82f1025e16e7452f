#include "scanner/sim/virtual_scanner.hpp"

#include <gtest/gtest.h>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::sim {
namespace {

// The camera sits at the stand-off along the direction and looks back at the centre, with a proper
// rotation whose image x axis is level (normal to +z) unless the view is near vertical.
TEST(ViewFrom, TheCameraLooksAtTheCentreFromTheStandOff) {
  const Eigen::Vector3d centre(0.3, -1.2, 2.0);
  for (const Eigen::Vector3d& raw : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 2, -0.5),
                                     Eigen::Vector3d(0.1, 0.05, 1), Eigen::Vector3d(0, 0, -1)}) {
    const Eigen::Vector3d direction = raw.normalized();
    const Eigen::Isometry3d T_W_C = ViewFrom(centre, direction, 0.8);
    const Eigen::Matrix3d R = T_W_C.linear();
    EXPECT_LT((T_W_C.translation() - (centre + 0.8 * direction)).norm(), 1e-12);
    EXPECT_LT((R.col(2) + direction).norm(), 1e-12);  // z forward, towards the centre
    EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
    const Eigen::Vector3d up =
        std::abs(direction.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
    EXPECT_NEAR(R.col(0).dot(up), 0.0, 1e-12);
    EXPECT_LT(R.col(1).dot(up), 0.0);  // image y (down) leans away from up
  }
}

TEST(LookAt, AnEyeOnTheTargetOrAViewAlongUpIsRefused) {
  const Eigen::Vector3d p(1, 2, 3);
  EXPECT_THROW(LookAt(p, p, Eigen::Vector3d::UnitZ()), Error);
  EXPECT_THROW(LookAt(p, p + Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ()), Error);
}

}  // namespace
}  // namespace uwscan::scanner::sim
