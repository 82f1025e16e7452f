#include "scanner/calibration/viewport_calibration.hpp"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "scanner/calibration/pattern_pose.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/common/symmetrized.hpp"
#include "scanner/optics/refractive_camera.hpp"

namespace uwscan::scanner::calibration {
namespace {

constexpr int kMinViews = 3;
constexpr double kMinDistanceM = 1e-6;  // the camera centre stays inside the housing
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// A pattern pose as Ceres optimises it: angle-axis rotation, then translation (metres). One
// block per view, so that the Schur complement can eliminate the poses.
using Pose6 = std::array<double, 6>;

Pose6 ToPose6(const Eigen::Isometry3d& T) {
  const Eigen::AngleAxisd rotation(T.linear());
  const Eigen::Vector3d r = rotation.angle() * rotation.axis();
  return {r.x(), r.y(), r.z(), T.translation().x(), T.translation().y(), T.translation().z()};
}

Eigen::Isometry3d ToIsometry(const Pose6& pose) {
  const Eigen::Vector3d rotation(pose[0], pose[1], pose[2]);
  const double angle = rotation.norm();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (angle > 0.0) T.linear() = Eigen::AngleAxisd(angle, rotation / angle).toRotationMatrix();
  T.translation() = Eigen::Vector3d(pose[3], pose[4], pose[5]);
  return T;
}

// Reprojection residual of one corner (pixels) over its view's pose and the viewport.
struct ViewportResidual {
  ViewportResidual(const PinholeCamera& camera, double n_air, const Eigen::Vector3d& p_O,
                   const Eigen::Vector2d& uv_px)
      : camera(camera), n_air(n_air), p_O(p_O), uv_px(uv_px) {}

  template <typename T>
  bool operator()(const T* pose, const T* normal, const T* distance_m, const T* thickness_m,
                  const T* n_glass, const T* n_water, T* residual) const {
    const T p_O_T[3] = {T(p_O.x()), T(p_O.y()), T(p_O.z())};
    T p_C[3];
    ceres::AngleAxisRotatePoint(pose, p_O_T, p_C);
    for (int i = 0; i < 3; ++i) p_C[i] += pose[3 + i];
    T uv[2];
    if (!ProjectThroughViewport(camera, normal, *distance_m, *thickness_m, n_air, *n_glass,
                                *n_water, p_C, uv)) {
      return false;
    }
    residual[0] = uv[0] - uv_px.x();
    residual[1] = uv[1] - uv_px.y();
    return true;
  }

  PinholeCamera camera;
  double n_air;
  Eigen::Vector3d p_O;
  Eigen::Vector2d uv_px;
};

// Every unknown, in the layout Ceres optimises.
struct Unknowns {
  std::array<double, 3> normal{};
  double distance_m = 0.0;
  double thickness_m = 0.0;
  double n_glass = 0.0;
  double n_water = 0.0;
  std::vector<Pose6> poses;
};

// Parameters with a lower bound the active set may hold them on: value, bound.
using Bounds = std::vector<std::pair<double*, double>>;

// Ends a solve (successfully) once a refined parameter has been on its lower bound for
// kStreak successive iterations: see SolveWithActiveSet.
class BoundWatcher final : public ceres::IterationCallback {
 public:
  static constexpr int kStreak = 5;

  BoundWatcher(const ceres::Problem& problem, const Bounds& bounded)
      : problem_(problem), bounded_(bounded) {}

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& /*summary*/) override {
    bool on_bound = false;
    for (const auto& [value, lower] : bounded_) {
      on_bound = on_bound || (!problem_.IsParameterBlockConstant(value) && *value <= lower);
    }
    streak_ = on_bound ? streak_ + 1 : 0;
    return streak_ >= kStreak ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }

  void Reset() { streak_ = 0; }

 private:
  const ceres::Problem& problem_;
  const Bounds& bounded_;
  int streak_ = 0;
};

// Every refined parameter's standard deviation to +infinity: not determined.
void MarkUndetermined(const ViewportCalibrationOptions& options,
                      ViewportCalibrationResult& result) {
  result.normal_std_rad = kInfinity;
  result.distance_std_m = kInfinity;
  if (options.refine_thickness) result.thickness_std_m = kInfinity;
  if (options.refine_glass_index) result.n_glass_std = kInfinity;
  if (options.refine_water_index) result.n_water_std = kInfinity;
}

// Standard deviations (and the distance-thickness correlation) from Ceres' covariance of the
// viewport blocks, scaled by the residual variance. Ceres factorises the Jacobian itself
// (sparse QR, rank-revealing): nothing here inverts normal equations.
void FillStandardDeviations(ceres::Problem& problem, Unknowns& x,
                            const ViewportCalibrationOptions& options, int residual_count,
                            double final_cost, ViewportCalibrationResult& result) {
  int parameter_count = 6 * static_cast<int>(x.poses.size()) + 2 + 1;
  if (options.refine_thickness) ++parameter_count;
  if (options.refine_glass_index) ++parameter_count;
  if (options.refine_water_index) ++parameter_count;
  const int dof = residual_count - parameter_count;

  std::vector<std::pair<const double*, const double*>> blocks = {{x.normal.data(), x.normal.data()},
                                                                 {&x.distance_m, &x.distance_m}};
  if (options.refine_thickness) {
    blocks.emplace_back(&x.thickness_m, &x.thickness_m);
    blocks.emplace_back(&x.distance_m, &x.thickness_m);
  }
  if (options.refine_glass_index) blocks.emplace_back(&x.n_glass, &x.n_glass);
  if (options.refine_water_index) blocks.emplace_back(&x.n_water, &x.n_water);

  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::SPARSE_QR;
  covariance_options.num_threads = 1;
  ceres::Covariance covariance(covariance_options);
  if (dof <= 0 || !covariance.Compute(blocks, &problem)) {
    MarkUndetermined(options, result);
    return;
  }
  const double sigma2 = 2.0 * final_cost / dof;
  const auto scalar_std = [&](const double* block) {
    double variance = 0.0;
    covariance.GetCovarianceBlock(block, block, &variance);
    return std::sqrt(std::max(0.0, variance * sigma2));
  };
  // The ambient 3x3 covariance of the unit normal has rank 2; for small errors a unit vector's
  // displacement is its rotation in radians, so the largest eigenvalue is the worse angle's
  // variance (the sphere manifold's own tangent coordinates are twice the angle).
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> normal_covariance;
  covariance.GetCovarianceBlock(x.normal.data(), x.normal.data(), normal_covariance.data());
  const Eigen::Matrix3d symmetric = Symmetrized(normal_covariance);
  const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(symmetric).eigenvalues()(2);
  result.normal_std_rad = std::sqrt(std::max(0.0, largest * sigma2));
  result.distance_std_m = scalar_std(&x.distance_m);
  if (options.refine_thickness) {
    result.thickness_std_m = scalar_std(&x.thickness_m);
    double cross = 0.0;
    covariance.GetCovarianceBlock(&x.distance_m, &x.thickness_m, &cross);
    const double scale = result.distance_std_m * result.thickness_std_m;
    if (scale > 0.0) result.distance_thickness_correlation = cross * sigma2 / scale;
  }
  if (options.refine_glass_index) result.n_glass_std = scalar_std(&x.n_glass);
  if (options.refine_water_index) result.n_water_std = scalar_std(&x.n_water);
}

// The camera through the CAD viewport, checked; its errors name CalibrateCameraViewport.
RefractiveCamera CheckedCadCamera(const PinholeCamera& intrinsics, const FlatViewport& initial) {
  const RefractiveCamera cad{intrinsics, initial};
  try {
    cad.Check();
  } catch (const Error& e) {
    throw Error(std::string("CalibrateCameraViewport: ") + e.what());
  }
  return cad;
}

// Every view's corners and its pattern pose through the CAD viewport (the fit's start).
struct ViewStarts {
  std::vector<CornerCorrespondences> views;
  std::vector<Pose6> poses;
};

ViewStarts MatchAndPoseViews(const RefractiveCamera& cad, const PatternSpec& spec,
                             const std::vector<PatternObservation>& observations) {
  ViewStarts start;
  start.views.reserve(observations.size());
  for (std::size_t i = 0; i < observations.size(); ++i) {
    try {
      start.views.push_back(MatchCorners(spec, observations[i], static_cast<int>(i)));
      start.poses.push_back(ToPose6(EstimatePatternPose(cad, spec, observations[i]).T_C_O));
    } catch (const Error& e) {
      throw Error("CalibrateCameraViewport: view " + std::to_string(i) + ": " + e.what());
    }
  }
  return start;
}

// The start: the CAD viewport and the given pattern poses.
Unknowns UnknownsAt(const FlatViewport& initial, std::vector<Pose6> poses) {
  Unknowns x;
  x.normal = {initial.normal.x(), initial.normal.y(), initial.normal.z()};
  x.distance_m = initial.distance_m;
  x.thickness_m = initial.thickness_m;
  x.n_glass = initial.n_glass;
  x.n_water = initial.n_water;
  x.poses = std::move(poses);
  return x;
}

// One reprojection residual per corner, view by view; each view's pose goes to the group the
// Schur complement eliminates first. Returns the number of residuals.
int AddCornerResiduals(const PinholeCamera& intrinsics, double n_air,
                       const std::vector<CornerCorrespondences>& views, Unknowns& x,
                       ceres::Problem& problem, ceres::ParameterBlockOrdering& ordering) {
  int residual_count = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    for (std::size_t j = 0; j < views[i].points_O.size(); ++j) {
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<ViewportResidual, 2, 6, 3, 1, 1, 1, 1>(
              new ViewportResidual(intrinsics, n_air, views[i].points_O[j], views[i].pixels[j])),
          nullptr, x.poses[i].data(), x.normal.data(), &x.distance_m, &x.thickness_m, &x.n_glass,
          &x.n_water);
      residual_count += 2;
    }
    ordering.AddElementToGroup(x.poses[i].data(), 0);  // eliminated first (Schur)
  }
  return residual_count;
}

// The viewport's blocks: the normal on the unit sphere, bounds, the parameters not refined held,
// and all of them in the second group of the ordering.
void BoundAndHoldViewport(double n_air, const ViewportCalibrationOptions& options, Unknowns& x,
                          ceres::Problem& problem, ceres::ParameterBlockOrdering& ordering) {
  problem.SetManifold(x.normal.data(), new ceres::SphereManifold<3>);
  // The camera centre stays inside the housing and the slab keeps a thickness; the indices
  // stay physical (denser than air) when refined.
  problem.SetParameterLowerBound(&x.distance_m, 0, kMinDistanceM);
  problem.SetParameterLowerBound(&x.thickness_m, 0, 0.0);
  for (double* index : {&x.n_glass, &x.n_water}) {
    problem.SetParameterLowerBound(index, 0, n_air);
    problem.SetParameterUpperBound(index, 0, 3.0);
  }
  if (!options.refine_thickness) problem.SetParameterBlockConstant(&x.thickness_m);
  if (!options.refine_glass_index) problem.SetParameterBlockConstant(&x.n_glass);
  if (!options.refine_water_index) problem.SetParameterBlockConstant(&x.n_water);
  for (double* block : {x.normal.data(), &x.distance_m, &x.thickness_m, &x.n_glass, &x.n_water}) {
    ordering.AddElementToGroup(block, 1);
  }
}

ceres::Solver::Options SolverOptions(const ViewportCalibrationOptions& options,
                                     std::shared_ptr<ceres::ParameterBlockOrdering> ordering) {
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_SCHUR;
  solver_options.linear_solver_ordering = std::move(ordering);
  solver_options.max_num_iterations = options.max_iterations;
  // Units differ by orders of magnitude (pixels per metre of distance, per radian of normal,
  // per unit of index); Ceres' Jacobi scaling (on by default) equalises the columns, so the
  // trust region is not dominated by one unit. Tolerances are tight so that exact data reach
  // round-off; the cost of noisy data stalls well before that and ends on the step size.
  solver_options.jacobi_scaling = true;
  solver_options.function_tolerance = 1e-15;
  solver_options.gradient_tolerance = 0.0;
  solver_options.parameter_tolerance = 1e-14;
  solver_options.num_threads = 1;  // deterministic
  solver_options.logging_type = ceres::SILENT;
  return solver_options;
}

// Holds every refined parameter that has reached its lower bound there; returns whether one did.
bool PinParametersOnBounds(const Bounds& bounded, ceres::Problem& problem,
                           std::vector<double*>& pinned) {
  bool pinned_one = false;
  for (const auto& [value, lower] : bounded) {
    if (!problem.IsParameterBlockConstant(value) && *value <= lower) {
      *value = lower;
      problem.SetParameterBlockConstant(value);
      pinned.push_back(value);
      pinned_one = true;
    }
  }
  return pinned_one;
}

struct SolveOutcome {
  ceres::Solver::Summary summary;  // of the last solve
  int iterations = 0;              // over all solves
};

// Active set. Ceres keeps bounds by projecting each step onto the box; when the optimum lies on
// a bound and the parameter is strongly correlated with others (the thickness with the distance
// and every pose), the projected steps are poor and LM crawls along the bound for hundreds of
// iterations. So a solve ends once a refined parameter has sat on its bound for a few
// iterations; that parameter is then held on the bound and the rest solved again, which reaches
// the constrained optimum directly.
SolveOutcome SolveWithActiveSet(ceres::Solver::Options solver_options, const Bounds& bounded,
                                ceres::Problem& problem) {
  BoundWatcher watcher(problem, bounded);
  solver_options.callbacks.push_back(&watcher);
  solver_options.update_state_every_iteration = true;  // the watcher reads the parameters
  SolveOutcome outcome;
  std::vector<double*> pinned;
  for (std::size_t round = 0; round <= bounded.size(); ++round) {
    watcher.Reset();
    ceres::Solve(solver_options, &problem, &outcome.summary);
    outcome.iterations += std::max(0, static_cast<int>(outcome.summary.iterations.size()) - 1);
    if (outcome.summary.termination_type == ceres::FAILURE) break;
    if (!PinParametersOnBounds(bounded, problem, pinned)) break;
  }
  // The covariance describes the model without the bound: how far the data leave the
  // parameter undetermined, which is why it reached the bound.
  for (double* value : pinned) problem.SetParameterBlockVariable(value);
  return outcome;
}

FlatViewport ViewportOf(const FlatViewport& initial, const Unknowns& x) {
  FlatViewport viewport = initial;
  viewport.normal = Eigen::Vector3d(x.normal[0], x.normal[1], x.normal[2]).normalized();
  viewport.distance_m = x.distance_m;
  viewport.thickness_m = x.thickness_m;
  viewport.n_glass = x.n_glass;
  viewport.n_water = x.n_water;
  return viewport;
}

// The fitted viewport and pattern poses, with the corners' 2-D reprojection errors at them
// (recomputed with the double path for the reported figures).
ViewportCalibrationResult FittedResult(const PinholeCamera& intrinsics, const FlatViewport& initial,
                                       const std::vector<CornerCorrespondences>& views,
                                       const Unknowns& x) {
  ViewportCalibrationResult result;
  result.viewport = ViewportOf(initial, x);
  const RefractiveCamera fitted{intrinsics, result.viewport};
  double sum_sq = 0.0;
  int corners = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const Eigen::Isometry3d T_C_O = ToIsometry(x.poses[i]);
    result.T_C_O.push_back(T_C_O);
    double view_sq = 0.0;
    for (std::size_t j = 0; j < views[i].points_O.size(); ++j) {
      const std::optional<Eigen::Vector2d> uv =
          fitted.ProjectPointInWater(T_C_O * views[i].points_O[j]);
      const double error = uv ? (*uv - views[i].pixels[j]).norm() : kInfinity;
      view_sq += error * error;
      result.max_px = std::max(result.max_px, error);
    }
    sum_sq += view_sq;
    corners += static_cast<int>(views[i].points_O.size());
    result.view_rms_px.push_back(
        std::sqrt(view_sq / static_cast<double>(views[i].points_O.size())));
  }
  result.rms_px = std::sqrt(sum_sq / corners);
  return result;
}

}  // namespace

void ViewportCalibrationOptions::Check() const {
  OptionChecks("ViewportCalibrationOptions").GreaterThan("max_iterations", max_iterations, 0);
}

ViewportCalibrationResult CalibrateCameraViewport(
    const PinholeCamera& intrinsics, const FlatViewport& initial, const PatternSpec& spec,
    const std::vector<PatternObservation>& observations,
    const ViewportCalibrationOptions& options) {
  options.Check();
  spec.Check();
  const RefractiveCamera cad = CheckedCadCamera(intrinsics, initial);
  if (static_cast<int>(observations.size()) < kMinViews) {
    throw Error("CalibrateCameraViewport: " + std::to_string(observations.size()) +
                " views, need at least " + std::to_string(kMinViews));
  }
  ViewStarts start = MatchAndPoseViews(cad, spec, observations);
  Unknowns x = UnknownsAt(initial, std::move(start.poses));
  const std::vector<CornerCorrespondences>& views = start.views;

  // The problem holds pointers into x: x stays where it is from here on.
  ceres::Problem problem;
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  const int residual_count =
      AddCornerResiduals(intrinsics, initial.n_air, views, x, problem, *ordering);
  BoundAndHoldViewport(initial.n_air, options, x, problem, *ordering);
  const Bounds bounded = {{&x.distance_m, kMinDistanceM},
                          {&x.thickness_m, 0.0},
                          {&x.n_glass, initial.n_air},
                          {&x.n_water, initial.n_air}};
  const SolveOutcome solved =
      SolveWithActiveSet(SolverOptions(options, ordering), bounded, problem);

  ViewportCalibrationResult result = FittedResult(intrinsics, initial, views, x);
  result.iterations = solved.iterations;
  result.converged = solved.summary.termination_type == ceres::CONVERGENCE;
  if (solved.summary.termination_type == ceres::FAILURE) {
    MarkUndetermined(options, result);  // no covariance of a failed solve
    return result;
  }
  FillStandardDeviations(problem, x, options, residual_count, solved.summary.final_cost, result);
  return result;
}

}  // namespace uwscan::scanner::calibration
