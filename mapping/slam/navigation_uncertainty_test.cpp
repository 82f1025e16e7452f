#include "mapping/slam/navigation_uncertainty.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

namespace uwscan::mapping::test {
namespace {

// A sweep as the mapper sees it: the stripe crosses a footprint centred ahead of and below the
// vehicle at a steady rate while the dead reckoning's position walks sideways. The rigid pose
// that best fits the frames as placed onto where they truly are is the submap's effective pose;
// its spread over many walks is what SubmapDistortionCovariance has to describe.
struct WalkingSweep {
  Eigen::Vector3d centre{0.7, 0.0, 1.0};  // footprint centre in the anchor's frame (m)
  double length_m = 0.7;                  // crossed by the stripe during the sweep, along x
  double width_m = 0.45;                  // the stripe's length, along y
  int frames = 51;
  int points_per_frame = 15;
  double span_s = 0.5;
};

std::vector<Eigen::Vector3d> Footprint(const WalkingSweep& g) {
  std::vector<Eigen::Vector3d> points;
  for (int k = 0; k < g.frames; ++k) {
    const double x = g.length_m * (static_cast<double>(k) / (g.frames - 1) - 0.5);
    for (int j = 0; j < g.points_per_frame; ++j) {
      const double y = g.width_m * (static_cast<double>(j) / (g.points_per_frame - 1) - 0.5);
      points.push_back(g.centre + Eigen::Vector3d(x, y, 0.0));
    }
  }
  return points;
}

double RmsRadius(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& centre) {
  double sum = 0.0;
  for (const Eigen::Vector3d& p : points) sum += (p - centre).squaredNorm();
  return std::sqrt(sum / static_cast<double>(points.size()));
}

// [w, v] of the best rigid fit of the frames placed with a walking position onto their truth,
// for `trials` walks pinned at the middle frame (the anchor).
std::vector<Vector6d> FittedOffsets(const WalkingSweep& g, double walk_m_per_sqrt_s, int trials) {
  const std::vector<Eigen::Vector3d> truth = Footprint(g);
  const double step = walk_m_per_sqrt_s * std::sqrt(g.span_s / (g.frames - 1));
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  std::vector<Vector6d> offsets;
  for (int trial = 0; trial < trials; ++trial) {
    std::vector<Eigen::Vector2d> walk(static_cast<size_t>(g.frames), Eigen::Vector2d::Zero());
    for (int k = 1; k < g.frames; ++k) {
      walk[static_cast<size_t>(k)] =
          walk[static_cast<size_t>(k - 1)] + step * Eigen::Vector2d{normal(rng), normal(rng)};
    }
    const Eigen::Vector2d anchor = walk[static_cast<size_t>(g.frames / 2)];
    Eigen::Matrix3Xd placed(3, static_cast<Eigen::Index>(truth.size())), actual(3, placed.cols());
    for (std::size_t i = 0; i < truth.size(); ++i) {
      const Eigen::Vector2d off = walk[i / static_cast<size_t>(g.points_per_frame)] - anchor;
      placed.col(static_cast<Eigen::Index>(i)) = truth[i] + Eigen::Vector3d(off.x(), off.y(), 0.0);
      actual.col(static_cast<Eigen::Index>(i)) = truth[i];
    }
    // The cloud placed in the anchor's frame, moved by T onto the truth: T is the effective pose.
    const Eigen::Isometry3d T(Eigen::umeyama(placed, actual, false));
    const Eigen::AngleAxisd turn(T.linear());
    Vector6d e;
    e << turn.angle() * turn.axis(), T.translation();
    offsets.push_back(e);
  }
  return offsets;
}

Matrix6d SampleCovariance(const std::vector<Vector6d>& samples) {
  Matrix6d c = Matrix6d::Zero();
  for (const Vector6d& s : samples) c += s * s.transpose();  // zero mean by symmetry
  return c / static_cast<double>(samples.size());
}

TEST(NavigationUncertainty, SubmapDistortionMatchesTheRigidFitOfAWalkingSweep) {
  const WalkingSweep g;
  NavigationNoise noise{0.003, 0.0, 0.0, 0.0, 0.0, 0.0};
  const NavigationUncertainty model(noise);
  const std::vector<Eigen::Vector3d> points = Footprint(g);
  // Heading 0.7 rad east of north, 0.25 m/s over the sweep: the model works in the anchor's frame.
  SweepPlacement sweep;
  const Eigen::Matrix3d R_W_V = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  sweep.T_W_start.linear() = sweep.T_W_anchor.linear() = sweep.T_W_end.linear() = R_W_V;
  sweep.T_W_anchor.translation() = R_W_V * Eigen::Vector3d(0.0625, 0.0, 0.0);
  sweep.T_W_end.translation() = R_W_V * Eigen::Vector3d(0.125, 0.0, 0.0);
  sweep.span_s = g.span_s;
  sweep.footprint_radius_m = RmsRadius(points, g.centre);
  sweep.footprint_centre_V = g.centre;
  const Matrix6d predicted = model.SubmapDistortionCovariance(sweep, SystematicErrors::kEstimated);
  const Matrix6d measured =
      SampleCovariance(FittedOffsets(g, noise.position_walk_m_per_sqrt_s, 4000));

  // The turn the fit takes from the sideways walk, within a quarter of the model's.
  const double yaw_measured = std::sqrt(measured(2, 2)), yaw_predicted = std::sqrt(predicted(2, 2));
  EXPECT_NEAR(yaw_measured / yaw_predicted, 1.0, 0.25)
      << yaw_measured << " rad measured, " << yaw_predicted;
  // The turn happens about the footprint's centre: at the vehicle's origin, 0.7 m behind it, a
  // turn comes with a sideways shift of the opposite sign (v_y = -c_x w_z).
  const double corr_measured = measured(2, 4) / std::sqrt(measured(2, 2) * measured(4, 4));
  const double corr_predicted = predicted(2, 4) / std::sqrt(predicted(2, 2) * predicted(4, 4));
  EXPECT_LT(corr_measured, -0.5);
  EXPECT_NEAR(corr_measured, corr_predicted, 0.15);
  const double y_measured = std::sqrt(measured(4, 4)), y_predicted = std::sqrt(predicted(4, 4));
  EXPECT_NEAR(y_measured / y_predicted, 1.0, 0.35) << y_measured << " m measured, " << y_predicted;
  // Along the sweep the shift is the walk averaged over it: the model errs on the safe side.
  EXPECT_LE(std::sqrt(measured(3, 3)), std::sqrt(predicted(3, 3)));
  EXPECT_GE(std::sqrt(measured(3, 3)), 0.4 * std::sqrt(predicted(3, 3)));
}

}  // namespace
}  // namespace uwscan::mapping::test
