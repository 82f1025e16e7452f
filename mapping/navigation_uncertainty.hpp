#pragma once

#include <Eigen/Geometry>

#include "mapping/dive_log.hpp"
#include "mapping/pose_graph.hpp"

namespace uwscan::mapping {

// What the navigation's noise model says about its own estimates, in the pose graph's error
// convention (pose_graph.hpp: [w (rad), v (m)], a left perturbation in the first pose's frame).
// Each noise value is floored (kFloor... below) so a dive simulated without drift still gives
// finite information.
class NavigationUncertainty {
 public:
  explicit NavigationUncertainty(const NavigationNoise& noise);

  const NavigationNoise& noise() const { return noise_; }  // floored

  // Covariance of the dead-reckoned motion from a to b (their navigation poses, dt apart):
  // x, y and heading from the dead reckoning (random walks over dt, the speed scale error
  // along the motion, the heading bias across it); depth, roll and pitch differences from the
  // absolute sensors (twice their variance).
  Matrix6d IncrementCovariance(const Eigen::Isometry3d& T_W_a, const Eigen::Isometry3d& T_W_b,
                               double dt_s) const;

  // How much the navigation may have bent a submap whose frames it placed while the vehicle
  // went from a to b (span_s): the dead-reckoning covariance over that span, plus the tilt a
  // change of depth error across the submap's length would give (depth errors are not white).
  // Added to a registration's own covariance: scan matching cannot be more certain than the
  // shapes it matches are rigid. In a's frame.
  Matrix6d SubmapDistortionCovariance(const Eigen::Isometry3d& T_W_a, const Eigen::Isometry3d& T_W_b,
                                      double span_s) const;

  // Information of the same motion in x, y and heading only, zero in depth, roll and pitch:
  // the odometry edge of the graph, where absolute priors hold those three.
  Matrix6d OdometryInformation(const Eigen::Isometry3d& T_W_a, const Eigen::Isometry3d& T_W_b,
                               double dt_s) const;

 private:
  NavigationNoise noise_;
};

// The floors: below these a sensor is taken as exact to this much.
inline constexpr double kFloorWalk_m_per_sqrt_s = 1e-4;
inline constexpr double kFloorHeadingWalk_rad_per_sqrt_s = 1e-5;
inline constexpr double kFloorScale = 1e-4;
inline constexpr double kFloorHeadingBias_rad = 1e-5;
inline constexpr double kFloorDepth_m = 1e-4;
inline constexpr double kFloorRollPitch_rad = 1e-5;

// The information of (Sigma_a + Sigma_b) from the information a (possibly singular) and the
// covariance b (full rank), by Woodbury: L_a - L_a (L_a + Sigma_b^-1)^-1 L_a.
Matrix6d InformationOfSum(const Matrix6d& information_a, const Matrix6d& covariance_b);

// Ad(T) for the [w, v] left-perturbation convention: T exp(e) T^-1 = exp(Ad(T) e).
Matrix6d Adjoint(const Eigen::Isometry3d& T);

}  // namespace uwscan::mapping
