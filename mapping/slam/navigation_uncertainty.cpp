#include "mapping/slam/navigation_uncertainty.hpp"

#include <algorithm>

#include "scanner/common/symmetrized.hpp"

namespace uwscan::mapping {
namespace {

// A footprint smaller than this is taken as this large when its turn and tilt are bounded.
constexpr double kMinFootprintRadius_m = 0.1;
// The share of the sideways walk's variance over a sweep (over the footprint's squared RMS
// radius) that a rigid fit takes as a turn. For a Brownian path whose frames cross the
// footprint at a steady rate, the least-squares slope has variance 1.2 sigma^2 T over the
// squared extent crossed, 12 times the squared RMS radius of a uniform spread: 0.1.
constexpr double kTurnShare = 0.1;

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// A covariance expressed along the world's axes, re-expressed in frame a (both blocks rotate).
Matrix6d WorldAxesToFrame(const Matrix6d& in_world_axes, const Eigen::Matrix3d& R_W_a) {
  Matrix6d B = Matrix6d::Zero();
  B.topLeftCorner<3, 3>() = R_W_a.transpose();
  B.bottomRightCorner<3, 3>() = R_W_a.transpose();
  return B * in_world_axes * B.transpose();
}

// The information in heading, x and y (about the world's axes) of a covariance of a motion
// from a (in a's frame), zero in depth, roll and pitch.
Matrix6d HeadingAndPositionInformation(const Matrix6d& covariance_in_a,
                                       const Eigen::Isometry3d& T_W_a) {
  // Heading, x and y (world axes 2, 3, 4) inverted together; the other three carry nothing.
  const Matrix6d world_cov = WorldAxesToFrame(covariance_in_a, T_W_a.linear().transpose());
  const int kept[3] = {2, 3, 4};
  Eigen::Matrix3d sub;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) sub(r, c) = world_cov(kept[r], kept[c]);
  }
  const Eigen::Matrix3d sub_info = sub.inverse();
  Matrix6d world_info = Matrix6d::Zero();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) world_info(kept[r], kept[c]) = sub_info(r, c);
  }
  // Information transforms with the inverse of the covariance's map: e_W = B^-1 e_a, B
  // orthogonal, so the same rotation applies.
  return WorldAxesToFrame(world_info, T_W_a.linear());
}

}  // namespace

Matrix6d Adjoint(const Eigen::Isometry3d& T) {
  Matrix6d ad = Matrix6d::Zero();
  const Eigen::Matrix3d& R = T.linear();
  ad.topLeftCorner<3, 3>() = R;
  ad.bottomLeftCorner<3, 3>() = Skew(T.translation()) * R;
  ad.bottomRightCorner<3, 3>() = R;
  return ad;
}

NavigationUncertainty::NavigationUncertainty(const NavigationNoise& noise) : noise_(noise) {
  noise_.Check();
  noise_.position_walk_m_per_sqrt_s =
      std::max(noise_.position_walk_m_per_sqrt_s, kFloorWalk_m_per_sqrt_s);
  noise_.heading_walk_rad_per_sqrt_s =
      std::max(noise_.heading_walk_rad_per_sqrt_s, kFloorHeadingWalk_rad_per_sqrt_s);
  noise_.speed_scale_sigma = std::max(noise_.speed_scale_sigma, kFloorScale);
  noise_.heading_bias_sigma_rad = std::max(noise_.heading_bias_sigma_rad, kFloorHeadingBias_rad);
  noise_.depth_sigma_m = std::max(noise_.depth_sigma_m, kFloorDepth_m);
  noise_.roll_pitch_sigma_rad = std::max(noise_.roll_pitch_sigma_rad, kFloorRollPitch_rad);
}

Matrix6d NavigationUncertainty::IncrementCovariance(const Eigen::Isometry3d& T_W_a,
                                                    const Eigen::Isometry3d& T_W_b, double dt_s,
                                                    SystematicErrors systematic) const {
  const double dt = std::max(dt_s, 0.0);
  const Eigen::Vector2d moved = (T_W_b.translation() - T_W_a.translation()).head<2>();
  const double distance = moved.norm();
  Matrix6d world = Matrix6d::Zero();
  const double tilt = 2.0 * noise_.roll_pitch_sigma_rad * noise_.roll_pitch_sigma_rad;
  world(0, 0) = tilt;
  world(1, 1) = tilt;
  world(2, 2) = noise_.heading_walk_rad_per_sqrt_s * noise_.heading_walk_rad_per_sqrt_s * dt;
  Eigen::Matrix2d xy = Eigen::Matrix2d::Identity() *
                       (noise_.position_walk_m_per_sqrt_s * noise_.position_walk_m_per_sqrt_s * dt);
  if (distance > 0.0 && systematic == SystematicErrors::kAsNoise) {
    const Eigen::Vector2d along = moved / distance;
    const Eigen::Vector2d across(-along.y(), along.x());
    const double scale = noise_.speed_scale_sigma * distance;
    const double bias = noise_.heading_bias_sigma_rad * distance;
    xy += scale * scale * along * along.transpose() + bias * bias * across * across.transpose();
  }
  world.block<2, 2>(3, 3) = xy;
  world(5, 5) = 2.0 * noise_.depth_sigma_m * noise_.depth_sigma_m;
  return WorldAxesToFrame(world, T_W_a.linear());
}

Matrix6d NavigationUncertainty::SubmapDistortionCovariance(const SweepPlacement& sweep,
                                                           SystematicErrors systematic) const {
  const double span_s = std::max(sweep.span_s, 0.0);
  const double walk2 =
      noise_.position_walk_m_per_sqrt_s * noise_.position_walk_m_per_sqrt_s * span_s;
  const double radius = std::max(sweep.footprint_radius_m, kMinFootprintRadius_m);
  // About the footprint's centre, along the world's axes.
  Matrix6d at_centre = Matrix6d::Zero();
  // Roll and pitch: the depth error changing as the stripe crosses the footprint (at most the
  // difference of two independent errors), taken by the fit as a tilt as the sideways walk is
  // taken as a turn. The footprint's RMS radius spans all three axes, not only the one the
  // stripe crosses, so both shares err on the cautious side.
  at_centre(0, 0) = at_centre(1, 1) =
      kTurnShare * 2.0 * noise_.depth_sigma_m * noise_.depth_sigma_m / (radius * radius);
  // Heading: the sideways walk of the frames as the stripe crosses the footprint.
  at_centre(2, 2) = kTurnShare * walk2 / (radius * radius);
  // Position: the walk since the anchor averaged over the span (a third of its variance at the
  // ends, the rigid fit's share of a Brownian path pinned at the middle, with margin).
  Eigen::Matrix2d xy = Eigen::Matrix2d::Identity() * (walk2 / 3.0);
  const Eigen::Vector2d moved =
      (sweep.T_W_end.translation() - sweep.T_W_start.translation()).head<2>();
  const double distance = moved.norm();
  if (distance > 0.0 && systematic == SystematicErrors::kAsNoise) {
    // Stretched by the scale error and sheared by the misalignment about the middle.
    const Eigen::Vector2d along = moved / distance;
    const Eigen::Vector2d across(-along.y(), along.x());
    const double scale = 0.5 * noise_.speed_scale_sigma * distance;
    const double bias = 0.5 * noise_.heading_bias_sigma_rad * distance;
    xy += scale * scale * along * along.transpose() + bias * bias * across * across.transpose();
  }
  at_centre.block<2, 2>(3, 3) = xy;
  at_centre(5, 5) = noise_.depth_sigma_m * noise_.depth_sigma_m;
  // At the vehicle's origin (the anchor) a turn w about the centre also moves it by -w x centre.
  Matrix6d about_origin = Matrix6d::Identity();
  about_origin.bottomLeftCorner<3, 3>() = Skew(sweep.footprint_centre_V);
  const Eigen::Matrix3d& R_W_anchor = sweep.T_W_anchor.linear();
  Matrix6d covariance =
      about_origin * WorldAxesToFrame(at_centre, R_W_anchor) * about_origin.transpose();
  // The heading's own walk turns the frames about the vehicle, not about the footprint.
  Matrix6d own_heading = Matrix6d::Zero();
  own_heading(2, 2) =
      noise_.heading_walk_rad_per_sqrt_s * noise_.heading_walk_rad_per_sqrt_s * span_s;
  covariance += WorldAxesToFrame(own_heading, R_W_anchor);
  // A submap of one frame is not bent at all; its covariance still has to be invertible.
  for (int k = 0; k < 6; ++k) {
    covariance(k, k) +=
        k < 3 ? kFloorHeadingBias_rad * kFloorHeadingBias_rad : kFloorDepth_m * kFloorDepth_m;
  }
  return covariance;
}

Matrix6d NavigationUncertainty::BendingCovariance(double span_s, double footprint_radius_m) const {
  const double bridge2 = 0.25 * noise_.position_walk_m_per_sqrt_s *
                         noise_.position_walk_m_per_sqrt_s * std::max(span_s, 0.0);
  const double radius = std::max(footprint_radius_m, kMinFootprintRadius_m);
  Matrix6d covariance = Matrix6d::Zero();
  covariance.diagonal() << Eigen::Vector3d::Constant(bridge2 / (radius * radius)),
      Eigen::Vector3d::Constant(bridge2);
  return covariance;
}

Matrix6d InformationOfSum(const Matrix6d& information_a, const Matrix6d& covariance_b) {
  const Matrix6d information_b = covariance_b.inverse();
  const Matrix6d inner = (information_a + information_b).inverse();
  const Matrix6d sum = information_a - information_a * inner * information_a;
  return Symmetrized(sum);
}

Matrix6d NavigationUncertainty::OdometryInformation(const Eigen::Isometry3d& T_W_a,
                                                    const Eigen::Isometry3d& T_W_b, double dt_s,
                                                    SystematicErrors systematic) const {
  return HeadingAndPositionInformation(IncrementCovariance(T_W_a, T_W_b, dt_s, systematic), T_W_a);
}

}  // namespace uwscan::mapping
