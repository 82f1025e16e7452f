#pragma once

#include <Eigen/Geometry>

#include "mapping/log/dive_log.hpp"
#include "mapping/slam/pose_graph.hpp"

namespace uwscan::mapping {

// A submap's sweep as the navigation placed it: what its bending depends on.
struct SweepPlacement {
  // The navigation at the sweep's first, middle (the anchor) and last frame.
  Eigen::Isometry3d T_W_start = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_W_anchor = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_W_end = Eigen::Isometry3d::Identity();
  double span_s = 0.0;              // first to last frame
  double footprint_radius_m = 0.0;  // RMS distance of its points from their centre
  Eigen::Vector3d footprint_centre_V = Eigen::Vector3d::Zero();  // in the anchor's frame
};

// Whether a dead-reckoned motion's covariance holds the speed scale error and the misalignment
// (kAsNoise), or leaves them out because the pose graph estimates them (kEstimated,
// dead_reckoning_calibration.hpp).
enum class SystematicErrors { kAsNoise, kEstimated };

// What the navigation's noise model says about its own estimates, in the pose graph's error
// convention (pose_graph.hpp: [w (rad), v (m)], a left perturbation in the first pose's frame).
// Each noise value is floored (kFloor... below) so a dive simulated without drift still gives
// finite information.
class NavigationUncertainty {
 public:
  explicit NavigationUncertainty(const NavigationNoise& noise);

  const NavigationNoise& noise() const { return noise_; }  // floored

  // Covariance of the dead-reckoned motion from a to b (their navigation poses, dt apart):
  // x, y and heading from the dead reckoning (random walks over dt and, kAsNoise, the speed
  // scale error along the motion and the misalignment across it); depth, roll and pitch
  // differences from the absolute sensors (twice their variance).
  Matrix6d IncrementCovariance(const Eigen::Isometry3d& T_W_a, const Eigen::Isometry3d& T_W_b,
                               double dt_s,
                               SystematicErrors systematic = SystematicErrors::kAsNoise) const;

  // How far from its anchor's pose a submap, bent by the navigation that placed its frames, is
  // best fitted by a rigid pose: scan matching aligns shapes, so it measures that effective
  // pose, not the anchor's. The frames sit off by the random walk since the anchor; a rigid fit
  // over the span keeps about a third of its variance as a shift, and a tenth of its sideways
  // part over the footprint's squared RMS radius as a turn; depth errors across the footprint
  // tilt it; with kAsNoise, the scale error stretches it and the misalignment shears it about
  // the middle. All of this happens about the footprint's centre, so a turn also moves the
  // anchor's origin sideways; the heading's own walk turns it about the origin. As the
  // [w, v] of T_anchor_scan, in the anchor's frame. The graph's nodes are the effective poses:
  // this covariance goes into the navigation's edges and priors, not the registrations'.
  Matrix6d SubmapDistortionCovariance(
      const SweepPlacement& sweep, SystematicErrors systematic = SystematicErrors::kAsNoise) const;

  // What a rigid pose cannot take out of that bending: the random walk's departure from a
  // straight path over the span (half its spread at the middle), as a shift, and as a turn
  // across the footprint. Isotropic, so the same in any frame.
  Matrix6d BendingCovariance(double span_s, double footprint_radius_m) const;

  // Information of the same motion in x, y and heading only, zero in depth, roll and pitch:
  // the odometry edge of the graph, where absolute priors hold those three.
  Matrix6d OdometryInformation(const Eigen::Isometry3d& T_W_a, const Eigen::Isometry3d& T_W_b,
                               double dt_s,
                               SystematicErrors systematic = SystematicErrors::kAsNoise) const;

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
