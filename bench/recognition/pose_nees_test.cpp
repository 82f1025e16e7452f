#include "bench/recognition/pose_nees.hpp"

#include <gtest/gtest.h>

namespace uwscan::bench {
namespace {

// A pose turned about x through the centre by 2 sigma and slid along y by 1 sigma, with z left
// free (no covariance there) and slid far along it: (4 + 1 + 0 + 0 + 0) / 5 pinned directions.
TEST(PoseNees, CountsOnlyTheDirectionsTheCovariancePins) {
  const Eigen::Vector3d centre(0.3, -0.2, 0.1);
  Eigen::Matrix<double, 6, 6> covariance =
      Eigen::Matrix<double, 6, 6>::Identity() * 1e-6;  // 1 mrad, 1 mm
  covariance(5, 5) = 0.0;                              // slide along z free
  const Eigen::Isometry3d truth =
      Eigen::Translation3d(1.0, 2.0, 3.0) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY());
  // In the object frame: about x through the centre by 2 mrad, then 1 mm along y and 5 cm along z.
  const Eigen::Isometry3d delta =
      Eigen::Translation3d(0.0, 1e-3, 0.05) * Eigen::Translation3d(centre) *
      Eigen::AngleAxisd(2e-3, Eigen::Vector3d::UnitX()) * Eigen::Translation3d(-centre);
  const std::optional<double> nees =
      PoseNeesPerPinnedDirection(truth * delta, truth, centre, covariance);
  ASSERT_TRUE(nees.has_value());
  EXPECT_NEAR(*nees, 5.0 / 5.0, 1e-6);
  EXPECT_FALSE(PoseNeesPerPinnedDirection(truth, truth, centre, Eigen::Matrix<double, 6, 6>::Zero())
                   .has_value());
}

}  // namespace
}  // namespace uwscan::bench
