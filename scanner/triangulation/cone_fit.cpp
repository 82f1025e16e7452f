#include "scanner/triangulation/cone_fit.hpp"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/triangulation/light_plane.hpp"

namespace uwscan::scanner {
namespace {

constexpr double kPi = std::numbers::pi;

// Residual of one point: the model point g = T_C_Q (+) c(h, beta) minus the measured point,
// metres. With (h, beta) free per point its minimum over them is the orthogonal distance.
struct ConePointResidual {
  explicit ConePointResidual(const Eigen::Vector3d& p_C) : p_C(p_C) {}

  template <typename T>
  bool operator()(const T* q_wxyz, const T* t_C_Q, const T* ab, const T* h_beta,
                  T* residual) const {
    using std::cos;
    using std::sin;
    const T c_Q[3] = {ab[0] * h_beta[0] * cos(h_beta[1]), ab[1] * h_beta[0] * sin(h_beta[1]),
                      h_beta[0]};
    T c_C[3];
    ceres::UnitQuaternionRotatePoint(q_wxyz, c_Q, c_C);
    for (int i = 0; i < 3; ++i) {
      residual[i] = c_C[i] + t_C_Q[i] - T(p_C[i]);
    }
    return true;
  }

  Eigen::Vector3d p_C;
};

// All unknowns of the fit, in the layout Ceres optimises.
struct ConeParameters {
  std::array<double, 4> q_wxyz{};  // R_C_Q as a unit quaternion, w first (Ceres' order)
  std::array<double, 3> t_C_Q{};
  std::array<double, 2> ab{};
  std::vector<std::array<double, 2>> h_beta;  // per point: h (metres), beta (radians)
};

void CheckConeInput(std::span<const Eigen::Vector3d> points_in_C,
                    const Eigen::Vector3d& propagation_dir_in_C,
                    const Eigen::Vector3d& apex_hint_in_C) {
  if (points_in_C.size() < 6) {
    throw Error("FitCone: need at least 6 points, got " + std::to_string(points_in_C.size()));
  }
  for (std::size_t i = 0; i < points_in_C.size(); ++i) {
    if (!points_in_C[i].allFinite()) {
      throw Error("FitCone: point " + std::to_string(i) + " is not finite");
    }
  }
  if (!propagation_dir_in_C.allFinite() || propagation_dir_in_C.norm() == 0.0) {
    throw Error("FitCone: propagation_dir_in_C must be finite and non-zero");
  }
  if (!apex_hint_in_C.allFinite()) {
    throw Error("FitCone: apex_hint_in_C must be finite");
  }
}

// The start of the seed paper's fit: the light surface is nearly the plane of the points, so
// start from that plane (b small) with the fan's axis along the propagation direction.
ConeParameters PlaneStart(std::span<const Eigen::Vector3d> points_in_C,
                          const Eigen::Vector3d& propagation_dir_in_C,
                          const Eigen::Vector3d& apex_hint_in_C) {
  PlaneFit plane_fit;
  try {
    plane_fit = FitPlane(points_in_C);
  } catch (const Error& e) {
    throw Error(std::string("FitCone: ") + e.what());
  }
  const Plane& plane = plane_fit.plane;
  const Eigen::Vector3d y_axis = plane.normal;
  const Eigen::Vector3d dir = propagation_dir_in_C.normalized();
  const Eigen::Vector3d z_in_plane = dir - dir.dot(y_axis) * y_axis;
  if (z_in_plane.norm() < 1e-6) {
    throw Error("FitCone: propagation_dir_in_C is normal to the plane of the points");
  }
  const Eigen::Vector3d z_axis = z_in_plane.normalized();
  Eigen::Matrix3d R_C_Q;
  R_C_Q << y_axis.cross(z_axis), y_axis, z_axis;
  const Eigen::Vector3d apex_C =
      apex_hint_in_C - (y_axis.dot(apex_hint_in_C) - plane.offset_m) * y_axis;

  ConeParameters params;
  const Eigen::Quaterniond q(R_C_Q);
  params.q_wxyz = {q.w(), q.x(), q.y(), q.z()};
  params.t_C_Q = {apex_C.x(), apex_C.y(), apex_C.z()};

  std::vector<Eigen::Vector3d> points_Q;
  points_Q.reserve(points_in_C.size());
  double max_slope = 0.0;
  for (std::size_t i = 0; i < points_in_C.size(); ++i) {
    const Eigen::Vector3d p_Q = R_C_Q.transpose() * (points_in_C[i] - apex_C);
    if (!(p_Q.z() > 0.0)) {
      std::ostringstream message;
      message << "FitCone: point " << i << " is not ahead of apex_hint_in_C along "
              << "propagation_dir_in_C (z_Q = " << p_Q.z() << " m); give an apex hint behind "
              << "the lit points, e.g. the mirror";
      throw Error(message.str());
    }
    max_slope = std::max(max_slope, std::abs(p_Q.x() / p_Q.z()));
    points_Q.push_back(p_Q);
  }
  // 5 % wider than the widest point, so every start beta is well inside (0, pi) where acos is
  // not flat; the floor only guards points all on the axis.
  const double a = std::max(1.05 * max_slope, 1e-3);
  params.ab = {a, 1e-3};
  params.h_beta.reserve(points_Q.size());
  for (const Eigen::Vector3d& p_Q : points_Q) {
    params.h_beta.push_back({p_Q.z(), std::acos(std::clamp(p_Q.x() / (a * p_Q.z()), -1.0, 1.0))});
  }
  return params;
}

// The points' centroid and RMS distance from it.
struct Spread {
  Eigen::Vector3d centroid;
  double scale;
};

Spread SpreadOf(std::span<const Eigen::Vector3d> points) {
  const Eigen::Index n = static_cast<Eigen::Index>(points.size());
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) {
    centroid += p;
  }
  centroid /= static_cast<double>(n);
  double scale = 0.0;
  for (const Eigen::Vector3d& p : points) {
    scale += (p - centroid).squaredNorm();
  }
  return {centroid, std::sqrt(scale / static_cast<double>(n))};
}

// The quadric x^T M x + 2 w^T x + c = 0 in the units of a Spread (x = (p - centroid) / scale).
struct Quadric {
  Eigen::Matrix3d M;
  Eigen::Vector3d w;
};

// The algebraic (linear least squares) quadric through the points: the right singular vector of
// the smallest singular value. The points are centred and scaled to unit spread so that the ten
// monomials have comparable sizes.
Quadric FitQuadric(std::span<const Eigen::Vector3d> points, const Spread& spread) {
  const Eigen::Index n = static_cast<Eigen::Index>(points.size());
  Eigen::Matrix<double, Eigen::Dynamic, 10> design(n, 10);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d p = (points[i] - spread.centroid) / spread.scale;
    design.row(i) << p.x() * p.x(), p.y() * p.y(), p.z() * p.z(), 2.0 * p.x() * p.y(),
        2.0 * p.x() * p.z(), 2.0 * p.y() * p.z(), 2.0 * p.x(), 2.0 * p.y(), 2.0 * p.z(), 1.0;
  }
  const Eigen::JacobiSVD<Eigen::Matrix<double, Eigen::Dynamic, 10>> svd(design,
                                                                        Eigen::ComputeFullV);
  const Eigen::Matrix<double, 10, 1> v = svd.matrixV().col(9);
  Quadric quadric;
  quadric.M << v(0), v(3), v(4), v(3), v(1), v(5), v(4), v(5), v(2);
  quadric.w = Eigen::Vector3d(v(6), v(7), v(8));
  return quadric;
}

// The index of the eigenvalue of M with the odd sign, the cone's axis; std::nullopt when the
// quadric with these eigenvalues is not an elliptic cone.
std::optional<int> ConeAxis(const Eigen::Vector3d& lambda) {
  const double lambda_max = lambda.cwiseAbs().maxCoeff();
  if (!(lambda.cwiseAbs().minCoeff() > 1e-9 * lambda_max)) return std::nullopt;  // not a cone
  const int positives = static_cast<int>((lambda.array() > 0.0).count());
  if (positives == 0 || positives == 3) return std::nullopt;  // an ellipsoid, not a cone
  int k_axis = 0;
  for (int k = 0; k < 3; ++k) {
    if ((lambda(k) > 0.0) == (positives == 1)) {
      k_axis = k;
    }
  }
  return k_axis;
}

// The cone's frame {Q} from M's eigenvectors: z_Q along the axis (column k_axis), oriented towards
// the points; y_Q the other eigenvector closer to the fan's mean direction, as the lit sheet is
// centred on beta = pi/2, i.e. on the y_Q side; and which eigenvectors became x_Q and y_Q.
struct ConeFrame {
  Eigen::Matrix3d R_C_Q;
  int k_x;
  int k_y;
};

ConeFrame FrameOf(const Eigen::Matrix3d& eigenvectors, int k_axis, const Eigen::Vector3d& apex_C,
                  std::span<const Eigen::Vector3d> points_in_C) {
  Eigen::Vector3d z_axis = eigenvectors.col(k_axis);
  Eigen::Vector3d mean_dir = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points_in_C) {
    mean_dir += (p - apex_C).normalized();
  }
  if (mean_dir.dot(z_axis) < 0.0) {
    z_axis = -z_axis;
  }
  const int k1 = (k_axis + 1) % 3;
  const int k2 = (k_axis + 2) % 3;
  const bool k1_is_y =
      std::abs(eigenvectors.col(k1).dot(mean_dir)) >= std::abs(eigenvectors.col(k2).dot(mean_dir));
  ConeFrame frame;
  frame.k_y = k1_is_y ? k1 : k2;
  frame.k_x = k1_is_y ? k2 : k1;
  const Eigen::Vector3d y_axis = eigenvectors.col(frame.k_y);
  frame.R_C_Q << y_axis.cross(z_axis), y_axis, z_axis;
  return frame;
}

// The start on the cone with apex apex_C, orientation R_C_Q and cross-section slopes a, b: each
// point's (h, beta) read from its position in {Q}.
ConeParameters StartOnCone(std::span<const Eigen::Vector3d> points_in_C,
                           const Eigen::Matrix3d& R_C_Q, const Eigen::Vector3d& apex_C, double a,
                           double b) {
  ConeParameters params;
  const Eigen::Quaterniond q(R_C_Q);
  params.q_wxyz = {q.w(), q.x(), q.y(), q.z()};
  params.t_C_Q = {apex_C.x(), apex_C.y(), apex_C.z()};
  params.ab = {a, b};
  params.h_beta.reserve(points_in_C.size());
  for (const Eigen::Vector3d& p : points_in_C) {
    const Eigen::Vector3d p_Q = R_C_Q.transpose() * (p - apex_C);
    params.h_beta.push_back({p_Q.z(), std::atan2(p_Q.y() / b, p_Q.x() / a)});
  }
  return params;
}

// The second start (see FitCone): the algebraic (linear least squares) quadric
// x^T M x + 2 w^T x + c = 0 through the points, read as a cone: apex = its centre -M^-1 w, axis =
// the eigenvector of M whose eigenvalue has the odd sign, a and b from the other two. On bent
// fans it lands within a few percent of the optimum. nullopt when the quadric is not an
// elliptic cone (e.g. for planar points, where the plane start is right).
std::optional<ConeParameters> QuadricStart(std::span<const Eigen::Vector3d> points_in_C) {
  const Spread spread = SpreadOf(points_in_C);
  const Quadric quadric = FitQuadric(points_in_C, spread);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(quadric.M);
  const Eigen::Vector3d& lambda = eigen.eigenvalues();
  const std::optional<int> k_axis = ConeAxis(lambda);
  if (!k_axis) return std::nullopt;
  const Eigen::Vector3d apex_C =
      spread.centroid + spread.scale * (-quadric.M.inverse() * quadric.w);
  if (!apex_C.allFinite()) {
    return std::nullopt;
  }
  const ConeFrame frame = FrameOf(eigen.eigenvectors(), *k_axis, apex_C, points_in_C);
  // Normalised so that the axis eigenvalue is -1: then M ~ diag(1/a^2, 1/b^2, -1) in {Q}.
  const double inv_a_sq = lambda(frame.k_x) / -lambda(*k_axis);
  const double inv_b_sq = lambda(frame.k_y) / -lambda(*k_axis);
  const Eigen::Vector3d y_axis = frame.R_C_Q.col(1);
  double sum_y = 0.0;
  for (const Eigen::Vector3d& p : points_in_C) {
    sum_y += y_axis.dot(p - apex_C);
  }
  const double a = 1.0 / std::sqrt(inv_a_sq);
  const double b = std::copysign(1.0 / std::sqrt(inv_b_sq), sum_y);  // the points' sheet
  return StartOnCone(points_in_C, frame.R_C_Q, apex_C, a, b);
}

// Sum of squared residuals of a start, to choose between starts.
double StartCost(std::span<const Eigen::Vector3d> points_in_C, const ConeParameters& params) {
  double cost = 0.0;
  for (std::size_t i = 0; i < points_in_C.size(); ++i) {
    const ConePointResidual residual(points_in_C[i]);
    Eigen::Vector3d r;
    residual(params.q_wxyz.data(), params.t_C_Q.data(), params.ab.data(), params.h_beta[i].data(),
             r.data());
    cost += r.squaredNorm();
  }
  return std::isfinite(cost) ? cost : std::numeric_limits<double>::infinity();
}

ceres::Solver::Summary Solve(std::span<const Eigen::Vector3d> points_in_C,
                             const ConeFitOptions& options, ConeParameters& params) {
  ceres::Problem problem;
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (std::size_t i = 0; i < points_in_C.size(); ++i) {
    auto* cost = new ceres::AutoDiffCostFunction<ConePointResidual, 3, 4, 3, 2, 2>(
        new ConePointResidual(points_in_C[i]));
    problem.AddResidualBlock(cost, nullptr, params.q_wxyz.data(), params.t_C_Q.data(),
                             params.ab.data(), params.h_beta[i].data());
    ordering->AddElementToGroup(params.h_beta[i].data(), 0);  // eliminated first (Schur)
  }
  problem.SetManifold(params.q_wxyz.data(), new ceres::QuaternionManifold);
  ordering->AddElementToGroup(params.q_wxyz.data(), 1);
  ordering->AddElementToGroup(params.t_C_Q.data(), 1);
  ordering->AddElementToGroup(params.ab.data(), 1);

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_SCHUR;
  solver_options.linear_solver_ordering = ordering;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  // Exact data must reach rounding (rms ~1e-12 m); the gradient test would stop far earlier.
  solver_options.gradient_tolerance = 0.0;
  // Bent fans leave a nearly flat, curved valley (b, the axis tilt and a trade off against the
  // model misfit) where monotone LM takes hundreds of short steps; letting the cost rise
  // briefly cuts the median from ~130 to ~36 iterations on the default scanner's fans. The
  // result is still the lowest-cost iterate.
  solver_options.use_nonmonotonic_steps = true;
  solver_options.num_threads = 1;  // deterministic
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  return summary;
}

// Puts the solution in the form EllipticCone documents: a > 0 and the points on the sheet
// beta in [0, pi]. Both flips leave every model point where it is:
// c(h, beta; -a, b) = c(h, pi - beta; a, b) and c(h, -beta; a, -b) = c(h, beta; a, b).
void Normalise(ConeParameters& params) {
  if (params.ab[0] < 0.0) {
    params.ab[0] = -params.ab[0];
    for (auto& hb : params.h_beta) {
      hb[1] = kPi - hb[1];
    }
  }
  double sum_sin = 0.0;
  for (auto& hb : params.h_beta) {
    hb[1] = std::remainder(hb[1], 2.0 * kPi);  // into [-pi, pi]
    sum_sin += std::sin(hb[1]);
  }
  if (sum_sin < 0.0) {
    params.ab[1] = -params.ab[1];
    for (auto& hb : params.h_beta) {
      hb[1] = -hb[1];
    }
  }
}

}  // namespace

void ConeFitOptions::Check() const {
  const OptionChecks check("ConeFitOptions");
  check.GreaterThan("max_iterations", max_iterations, 0);
  check.NonNegative("function_tolerance", function_tolerance);
  check.NonNegative("parameter_tolerance", parameter_tolerance);
  check.Require(beta_margin_rad >= 0.0 && beta_margin_rad <= kPi, "beta_margin_rad",
                "in [0, pi] rad", beta_margin_rad);
}

ConeFit FitCone(std::span<const Eigen::Vector3d> points_in_C,
                const Eigen::Vector3d& propagation_dir_in_C, const Eigen::Vector3d& apex_hint_in_C,
                const ConeFitOptions& options) {
  options.Check();
  CheckConeInput(points_in_C, propagation_dir_in_C, apex_hint_in_C);
  ConeParameters params = PlaneStart(points_in_C, propagation_dir_in_C, apex_hint_in_C);
  if (options.algebraic_start) {
    std::optional<ConeParameters> quadric = QuadricStart(points_in_C);
    if (quadric && StartCost(points_in_C, *quadric) < StartCost(points_in_C, params)) {
      params = std::move(*quadric);
    }
  }
  const ceres::Solver::Summary summary = Solve(points_in_C, options, params);
  Normalise(params);

  ConeFit fit;
  fit.converged = summary.termination_type == ceres::CONVERGENCE;
  // summary.iterations starts with the evaluation at the initial point (iteration 0).
  fit.iterations = std::max(0, static_cast<int>(summary.iterations.size()) - 1);
  EllipticCone& cone = fit.cone;
  const auto& q = params.q_wxyz;
  cone.T_C_Q.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  cone.T_C_Q.translation() = Eigen::Vector3d(params.t_C_Q[0], params.t_C_Q[1], params.t_C_Q[2]);
  cone.a = params.ab[0];
  cone.b = params.ab[1];
  cone.h_min_m = 0.0;

  double beta_lo = kPi;
  double beta_hi = 0.0;
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < points_in_C.size(); ++i) {
    const auto& [h, beta] = params.h_beta[i];
    beta_lo = std::min(beta_lo, beta);
    beta_hi = std::max(beta_hi, beta);
    const double r = (cone.Point(h, beta) - points_in_C[i]).norm();
    sum_sq += r * r;
    fit.max_abs_m = std::max(fit.max_abs_m, r);
  }
  fit.rms_m = std::sqrt(sum_sq / static_cast<double>(points_in_C.size()));
  cone.beta_min_rad = std::clamp(beta_lo - options.beta_margin_rad, 0.0, kPi);
  cone.beta_max_rad = std::clamp(beta_hi + options.beta_margin_rad, 0.0, kPi);
  return fit;
}

}  // namespace uwscan::scanner
