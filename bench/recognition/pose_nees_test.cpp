#include "bench/recognition/pose_nees.hpp"

#include <gtest/gtest.h>

#include <vector>

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

// A free turn about an axis away from the centre (an elbow's bend): the covariance is zero along
// it in the metric the analysis used (rotations at the radius), 1 mm along the rest. The estimate
// is turned about that axis and slid 1 mm along x: only the slide counts, by its part off the
// free twist in that metric. Taken out by the pseudo-inverse alone, the turn would count too.
TEST(PoseNees, TakesTheReportedFreeTurnOutAsTheMotionItIs) {
  const double radius = 0.2, sigma = 1e-3, slide = 1e-3;
  const Eigen::Vector3d centre(0.05, 0.0, 0.0), point(0.15, 0.02, 0.0);
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  Eigen::Matrix<double, 6, 1> free_scaled;
  free_scaled << radius * axis, axis.cross(centre - point);
  free_scaled.normalize();
  Eigen::Matrix<double, 6, 6> D = Eigen::Matrix<double, 6, 6>::Identity();
  D.topLeftCorner<3, 3>() /= radius;
  const Eigen::Matrix<double, 6, 6> identity = Eigen::Matrix<double, 6, 6>::Identity();
  const Eigen::Matrix<double, 6, 6> covariance =
      D * (sigma * sigma * (identity - free_scaled * free_scaled.transpose())) * D;
  perception::FreeDirection turn;
  turn.motion = perception::FreeMotion::kRotation;
  turn.axis_S = axis;
  turn.point_S = point;
  const Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();  // scan frame = object frame
  // 0.02 rad: the turn's second-order motion of the centre (2e-4 x 10 cm) stays under 2 % of the
  // slide.
  const Eigen::Isometry3d estimate = Eigen::Translation3d(slide, 0.0, 0.0) *
                                     Eigen::Translation3d(point) * Eigen::AngleAxisd(0.02, axis) *
                                     Eigen::Translation3d(-point);
  const std::vector<perception::FreeDirection> free = {turn};
  const std::optional<double> nees =
      PoseNeesPerPinnedDirection(estimate, truth, centre, covariance, free);
  ASSERT_TRUE(nees.has_value());
  const double off_free = 1.0 - free_scaled[3] * free_scaled[3];  // the slide's share off it
  EXPECT_NEAR(*nees, off_free * (slide / sigma) * (slide / sigma) / 5.0, 0.05 * off_free / 5.0);
  EXPECT_GT(*PoseNeesPerPinnedDirection(estimate, truth, centre, covariance), 10.0 * *nees);
}

}  // namespace
}  // namespace uwscan::bench
