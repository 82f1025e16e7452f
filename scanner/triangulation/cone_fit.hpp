#pragma once

#include <Eigen/Core>
#include <span>

#include "scanner/triangulation/light_cone.hpp"

namespace uwscan::scanner {

struct ConeFitOptions {
  int max_iterations = 200;            // Levenberg-Marquardt iterations, > 0
  double function_tolerance = 1e-16;   // relative cost decrease that ends the fit, >= 0
  double parameter_tolerance = 1e-14;  // relative step size that ends the fit, >= 0
  double beta_margin_rad = 0.05;       // lit range = fitted beta range widened by this, >= 0
  bool algebraic_start = true;         // also try the algebraic quadric start (see FitCone)

  // Throws uwscan::Error naming the field when a value is out of range.
  void Check() const;
};

struct ConeFit {
  EllipticCone cone;       // pose, shape and lit range; h_min_m = 0
  double rms_m = 0.0;      // root mean square orthogonal distance of the points to the cone
  double max_abs_m = 0.0;  // largest orthogonal distance
  bool converged = false;  // the solver met a tolerance (not the iteration limit or a failure)
  int iterations = 0;      // solver iterations taken
};

// Fits an elliptic cone (see EllipticCone) to points sampled on a laser light surface, by
// nonlinear least squares on the seed paper's model g = T_C_Q (+) c(h, beta): the unknowns are
// the pose T_C_Q (unit quaternion + translation), a, b and one (h_i, beta_i) per point, and
// residual i = T_C_Q * c(h_i, beta_i) - p_i (metres), so at the optimum the cost is the sum of
// squared orthogonal distances. The per-point blocks are eliminated by a Schur complement, so
// the cost per iteration is linear in the number of points (~0.1 ms per 100 points).
//
// Starts. (1) The plane start: the total least squares plane of the points (FitPlane); y_Q =
// its normal, z_Q = propagation_dir_in_C projected into it, x_Q = y_Q x z_Q, the apex =
// apex_hint_in_C projected onto it; a = 1.05 max |x_Q / z_Q|, b = 1e-3 (nearly the plane; b
// is free in sign), h_i = z_Q,i, beta_i = acos(x_Q,i / (a z_Q,i)). A good apex hint is the
// mirror (the apex of the undistorted fan). (2) With options.algebraic_start, the algebraic
// quadric through the points read as a cone (apex = its centre, axis = its odd eigenvector).
// The fit runs from whichever start has the lower cost. Why two: for a fan refracted well off
// the viewport normal the optimum has its axis tilted out of the fan's plane and its apex far
// from the mirror, at the end of a curved, nearly flat valley (b, the tilt and a trade off
// against the model misfit) that LM crawls along from the plane start. On the default
// scanner's 201 steps (175 points each) the plane start alone needs a median of ~330
// iterations, the better of both ~36 (190 of 201 within the default 200; the rest are nearly
// planar fans, where the cone's shape is barely determined). Planar points have no algebraic
// cone, and the plane start is then exact.
// Result: a > 0 and beta_i normalised to the lit sheet; beta_min/max = range of the fitted
// beta_i widened by options.beta_margin_rad, clamped to [0, pi]; h_min_m = 0. Points that are
// exactly planar give |b| ~ 0 (the plane y_Q = 0). Single threaded and deterministic.
// Throws uwscan::Error on fewer than 6 points, a non-finite input, a propagation direction
// (nearly) normal to the points' plane or zero, points that do not span a plane, a point not
// ahead of the apex hint along the propagation direction (z_Q <= 0 at the start), or invalid
// options. A fit that does not converge is returned with converged = false.
ConeFit FitCone(std::span<const Eigen::Vector3d> points_in_C,
                const Eigen::Vector3d& propagation_dir_in_C, const Eigen::Vector3d& apex_hint_in_C,
                const ConeFitOptions& options = {});

}  // namespace uwscan::scanner
