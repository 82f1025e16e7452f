#include "scanner/calibration/galvo_laser_calibration.hpp"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>

#include "scanner/calibration/galvo_laser_simplified.hpp"
#include "scanner/calibration/jet_geometry.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/optics/refraction.hpp"
#include "scanner/triangulation/light_plane.hpp"

namespace uwscan::scanner::calibration {
namespace {

using galvo_simplified::EmitterFromEdgeRays;
using galvo_simplified::GroupBySteps;
using galvo_simplified::InAir;
using galvo_simplified::PointsByStep;
using galvo_simplified::Simplified;
using galvo_simplified::SimplifiedModel;
using jet::Value;
using jet::Vec3;
template <typename T>
using Mat3 = Eigen::Matrix<T, 3, 3>;
using Jet1 = ceres::Jet<double, 1>;

// ---------------------------------------------------------------------------------------------
// The fan of one mirror step, in a form that can carry Ceres Jets (derivatives).

template <typename T>
struct StepFan {
  Vec3<T> origin, central, spread;  // emitter, x_L, y_L
  Vec3<T> mirror_normal;
  T mirror_offset;  // reflecting surface: mirror_normal . x = mirror_offset

  template <typename U>
  StepFan<U> Cast() const {
    return {.origin = origin.template cast<U>(),
            .central = central.template cast<U>(),
            .spread = spread.template cast<U>(),
            .mirror_normal = mirror_normal.template cast<U>(),
            .mirror_offset = U(mirror_offset)};
  }
  StepFan<double> Values() const {
    const auto v = [](const Vec3<T>& x) {
      return Vec3<double>(Value(x[0]), Value(x[1]), Value(x[2]));
    };
    return {.origin = v(origin),
            .central = v(central),
            .spread = v(spread),
            .mirror_normal = v(mirror_normal),
            .mirror_offset = Value(mirror_offset)};
  }
};

StepFan<double> FanOfLaser(const GalvoLaser& laser, int step) {
  const LaserFan fan = laser.FanAtStep(step);
  return {fan.origin_C, fan.central_dir_C, fan.spread_dir_C, fan.mirror_normal_C,
          fan.mirror_offset_m};
}

// The fan ray of tangent s after the mirror and the viewport: LaserFan::RayInWater written for
// Jets (the same reflection and the same closed form as TraceOut). As lines: a start far from
// the answer may put the mirror or the viewport behind a ray, and the fit must still see a
// smooth distance there. false only where the formulas break down (a ray parallel to the
// mirror, or leaving the viewport backwards).
template <typename T>
bool TraceFanRay(const StepFan<T>& fan, const FlatViewport& v, const T& s, Vec3<T>& origin,
                 Vec3<T>& direction) {
  const Vec3<T> d = (fan.central + s * fan.spread).normalized();
  const T denom = fan.mirror_normal.dot(d);
  if (!(std::abs(Value(denom)) > 1e-15)) return false;
  const T t_mirror = (fan.mirror_offset - fan.mirror_normal.dot(fan.origin)) / denom;
  const Vec3<T> q = fan.origin + t_mirror * d;
  const Vec3<T> r = d - T(2.0) * d.dot(fan.mirror_normal) * fan.mirror_normal;
  if (!(Value(v.normal.cast<T>().dot(r)) > 1e-15)) return false;
  jet::TraceOutT(jet::Slab<T>{v.normal.cast<T>(), T(v.distance_m), T(v.thickness_m)}, v, q, r,
                 origin, direction);
  return true;
}

// The fan ray nearest a point: s minimises the distance |e_perp(s)| from p to the ray
// (Gauss-Newton in s, the ray's derivative in s by a one-dimensional Jet). At that s the unit
// vector `normal` = d x (tangent of the surface along s) is the light surface's normal at the
// foot of the perpendicular, parallel to e_perp.
struct NearestRay {
  double s = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double distance_m = 0.0;
};

std::optional<NearestRay> FindNearestRay(const StepFan<double>& fan, const FlatViewport& v,
                                         const Eigen::Vector3d& p) {
  // Start: without the viewport the ray through p points at p's mirror image from the emitter.
  const Eigen::Vector3d image =
      p - 2.0 * (fan.mirror_normal.dot(p) - fan.mirror_offset) * fan.mirror_normal;
  const double ahead = fan.central.dot(image - fan.origin);
  double s = ahead > 0.0 ? fan.spread.dot(image - fan.origin) / ahead : 0.0;
  const StepFan<Jet1> fan_jet = fan.Cast<Jet1>();
  for (int iteration = 0; iteration < 30; ++iteration) {
    Vec3<Jet1> o, d;
    if (!TraceFanRay(fan_jet, v, Jet1(s, 0), o, d)) return std::nullopt;
    const Eigen::Vector3d o_a(o[0].a, o[1].a, o[2].a), d_a(d[0].a, d[1].a, d[2].a);
    const Eigen::Vector3d o_s(o[0].v[0], o[1].v[0], o[2].v[0]);
    const Eigen::Vector3d d_s(d[0].v[0], d[1].v[0], d[2].v[0]);
    const Eigen::Vector3d e = p - o_a;
    const double t = e.dot(d_a);
    const Eigen::Vector3d e_perp = e - t * d_a;
    const Eigen::Vector3d w = o_s + t * d_s;  // where the foot moves as s grows
    const Eigen::Vector3d w_perp = w - w.dot(d_a) * d_a;
    const double w2 = w_perp.squaredNorm();
    if (!(w2 > 0.0) || !std::isfinite(w2)) return std::nullopt;
    const double step = e_perp.dot(w_perp) / w2;
    if (std::abs(step) <= 1e-15 * (1.0 + std::abs(s))) {
      return NearestRay{s, d_a.cross(w_perp).normalized(), e_perp.norm()};
    }
    s += step;
  }
  return std::nullopt;
}

// ---------------------------------------------------------------------------------------------
// Refinement unknowns: perturbations of the start, all zero at the start. Left out (held at
// the start's values, see the header): the turn of {L} about z_L0, the emitter's position in
// its plane, the mirror's zero angle (its turn about y_M0) and the mirror origin along y_M0.
//   R_C_L = R_L0 Exp(wL_x, wL_y, 0)     o   = o0 + uL z_L0
//   R_C_M = R_M0 Exp(wM_x, 0, wM_z)     t_M = t_M0 + R_M0 (vM_x, 0, vM_z)
struct Unknowns {
  std::array<double, 2> laser_rotation{};
  std::array<double, 1> laser_offset{};
  std::array<double, 2> mirror_rotation{};
  std::array<double, 2> mirror_position{};
  std::array<double, 1> mirror_step{};
  std::array<double, 1> rotation_distance{};
};

template <typename T>
Mat3<T> ExpRotation(const T& x, const T& y, const T& z) {
  const T w[3] = {x, y, z};
  Mat3<T> R;
  ceres::AngleAxisToRotationMatrix(w, R.data());  // column-major, as Eigen
  return R;
}

template <typename T>
void Poses(const GalvoLaser& start, const T* wL, const T* uL, const T* wM, const T* vM,
           Mat3<T>& R_L, Vec3<T>& o, Mat3<T>& R_M, Vec3<T>& t_M) {
  const Mat3<T> R_L0 = start.T_C_L.linear().cast<T>();
  const Mat3<T> R_M0 = start.T_C_M.linear().cast<T>();
  R_L = R_L0 * ExpRotation(wL[0], wL[1], T(0.0));
  o = start.T_C_L.translation().cast<T>() + uL[0] * R_L0.col(2);
  R_M = R_M0 * ExpRotation(wM[0], T(0.0), wM[1]);
  t_M = start.T_C_M.translation().cast<T>() + R_M0 * Vec3<T>(vM[0], T(0.0), vM[1]);
}

// Residual of one point: its signed distance from the light surface of its step. The nearest
// fan ray is found in doubles and its s held fixed while the Jets carry the derivatives: s
// minimises the distance, so the distance's derivative with respect to s vanishes there and
// the derivatives at fixed s are exact (envelope theorem); with `normal` fixed the same holds
// for the sign. This keeps the exact refracted fan (not a local approximation of its surface)
// and exact Jacobians at the cost of one short 1-D solve per point and evaluation.
class FanPointCost {
 public:
  FanPointCost(const GalvoLaser* start, int step, const Eigen::Vector3d& p_C)
      : start_(start), step_(step), p_C_(p_C) {}

  template <typename T>
  bool operator()(const T* wL, const T* uL, const T* wM, const T* vM, const T* rho, const T* delta,
                  T* residual) const {
    using std::cos;
    using std::sin;
    Mat3<T> R_L, R_M;
    Vec3<T> o, t_M;
    Poses(*start_, wL, uL, wM, vM, R_L, o, R_M, t_M);
    const T angle = T(static_cast<double>(step_)) * rho[0];
    StepFan<T> fan;
    fan.origin = o;
    fan.central = R_L.col(0);
    fan.spread = R_L.col(1);
    fan.mirror_normal = R_M * Vec3<T>(sin(angle), T(0.0), cos(angle));
    fan.mirror_offset = fan.mirror_normal.dot(t_M) + delta[0];
    const std::optional<NearestRay> nearest = FindNearestRay(fan.Values(), start_->viewport, p_C_);
    if (!nearest) return false;
    Vec3<T> ray_origin, ray_direction;
    if (!TraceFanRay(fan, start_->viewport, T(nearest->s), ray_origin, ray_direction)) {
      return false;
    }
    const Vec3<T> e = p_C_.cast<T>() - ray_origin;
    const Vec3<T> e_perp = e - e.dot(ray_direction) * ray_direction;
    residual[0] = e_perp.dot(nearest->normal.cast<T>());
    return true;
  }

 private:
  const GalvoLaser* start_;
  int step_;
  Eigen::Vector3d p_C_;
};

GalvoLaser LaserOf(const GalvoLaser& start, const Unknowns& x) {
  Mat3<double> R_L, R_M;
  Vec3<double> o, t_M;
  Poses(start, x.laser_rotation.data(), x.laser_offset.data(), x.mirror_rotation.data(),
        x.mirror_position.data(), R_L, o, R_M, t_M);
  GalvoLaser laser = start;
  // Re-orthonormalised: Exp is orthonormal only to rounding, and Check() demands 1e-9.
  laser.T_C_L.linear() = Eigen::Quaterniond(R_L).normalized().toRotationMatrix();
  laser.T_C_L.translation() = o;
  laser.T_C_M.linear() = Eigen::Quaterniond(R_M).normalized().toRotationMatrix();
  laser.T_C_M.translation() = t_M;
  laser.mirror_step_rad = x.mirror_step[0];
  laser.rotation_distance_m = x.rotation_distance[0];
  return laser;
}

// Builds the problem around `start` (whose values the unknowns perturb); returns the number
// of free unknowns.
int BuildProblem(const std::vector<LaserCalibrationPoint>& points, const GalvoLaser& start,
                 const GalvoLaserCalibrationOptions& options, Unknowns& x,
                 ceres::Problem& problem) {
  x = Unknowns{};
  x.mirror_step[0] = start.mirror_step_rad;
  x.rotation_distance[0] = start.rotation_distance_m;
  for (const LaserCalibrationPoint& point : points) {
    auto* cost = new ceres::AutoDiffCostFunction<FanPointCost, 1, 2, 1, 2, 2, 1, 1>(
        new FanPointCost(&start, point.mirror_step, point.p_C));
    problem.AddResidualBlock(cost, nullptr, x.laser_rotation.data(), x.laser_offset.data(),
                             x.mirror_rotation.data(), x.mirror_position.data(),
                             x.mirror_step.data(), x.rotation_distance.data());
  }
  int unknowns = 2 + 1 + 2 + 2 + 1 + 1;
  if (!options.refine_rotation_distance) {
    problem.SetParameterBlockConstant(x.rotation_distance.data());
    --unknowns;
  }
  return unknowns;
}

void CheckPoints(const std::vector<LaserCalibrationPoint>& points, const GalvoLaser& laser,
                 const char* who) {
  for (size_t k = 0; k < points.size(); ++k) {
    const LaserCalibrationPoint& point = points[k];
    if (!point.p_C.allFinite()) {
      throw Error(std::string(who) + ": point " + std::to_string(k) + " is not finite");
    }
    if (point.mirror_step < laser.step_min || point.mirror_step > laser.step_max) {
      throw Error(std::string(who) + ": point " + std::to_string(k) + " has mirror step " +
                  std::to_string(point.mirror_step) + ", outside the laser's step range [" +
                  std::to_string(laser.step_min) + ", " + std::to_string(laser.step_max) + "]");
    }
  }
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Passes of edge rays and refinement after the first refinement (CalibrateGalvoLaser).
constexpr int kEdgeRayPasses = 8;

// Standard deviations at the solution: the problem rebuilt around it (unknowns zero, so the
// perturbations are along the estimated frames' own axes), Ceres' covariance of the unknowns
// times the residual variance.
GalvoLaserStdDevs StdDevs(const std::vector<LaserCalibrationPoint>& points,
                          const GalvoLaser& solution, const GalvoLaserCalibrationOptions& options) {
  ceres::Problem problem;
  Unknowns x;
  const int unknowns = BuildProblem(points, solution, options, x, problem);
  double cost = 0.0;
  if (!problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr)) {
    return GalvoLaserStdDevs{Eigen::Vector3d::Constant(kNaN),
                             Eigen::Vector3d::Constant(kNaN),
                             Eigen::Vector2d::Constant(kNaN),
                             Eigen::Vector2d::Constant(kNaN),
                             kNaN,
                             kNaN};
  }
  const double dof = static_cast<double>(points.size()) - unknowns;
  const double variance = dof > 0.0 ? 2.0 * cost / dof : kNaN;

  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;  // small, and tells rank deficiency
  covariance_options.num_threads = 1;
  ceres::Covariance covariance(covariance_options);
  const std::vector<const double*> blocks = {x.laser_rotation.data(),  x.laser_offset.data(),
                                             x.mirror_rotation.data(), x.mirror_position.data(),
                                             x.mirror_step.data(),     x.rotation_distance.data()};
  std::vector<std::pair<const double*, const double*>> pairs;
  for (const double* block : blocks) {
    if (!problem.IsParameterBlockConstant(block)) pairs.emplace_back(block, block);
  }
  GalvoLaserStdDevs s;
  const bool ok = covariance.Compute(pairs, &problem);
  const auto sd = [&](const double* block, int size, int i) {
    if (!ok) return kNaN;
    if (problem.IsParameterBlockConstant(block)) return 0.0;
    std::array<double, 4> c{};  // blocks are at most 2 x 2
    covariance.GetCovarianceBlock(block, block, c.data());
    return std::sqrt(
        std::max(0.0, c[static_cast<size_t>(i) * static_cast<size_t>(size + 1)] * variance));
  };
  s.laser_rotation_rad = {sd(blocks[0], 2, 0), sd(blocks[0], 2, 1), 0.0};
  s.laser_position_m = {0.0, 0.0, sd(blocks[1], 1, 0)};
  s.mirror_axis_rad = {sd(blocks[2], 2, 0), sd(blocks[2], 2, 1)};
  s.mirror_position_m = {sd(blocks[3], 2, 0), sd(blocks[3], 2, 1)};
  s.mirror_step_rad = sd(blocks[4], 1, 0);
  s.rotation_distance_m = sd(blocks[5], 1, 0);
  return s;
}

// The refinement, on a laser traced in air.
GalvoLaserCalibrationResult Refine(const std::vector<LaserCalibrationPoint>& points,
                                   const GalvoLaser& start,
                                   const GalvoLaserCalibrationOptions& options) {
  ceres::Problem problem;
  Unknowns x;
  const int unknowns = BuildProblem(points, start, options, x, problem);
  if (static_cast<int>(points.size()) <= unknowns) {
    throw Error("RefineGalvoLaser: " + std::to_string(points.size()) + " points for " +
                std::to_string(unknowns) + " unknowns (need more points)");
  }
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  // Exact data must reach rounding (~1e-14 m), so no early stop on small relative changes.
  solver_options.function_tolerance = 1e-16;
  solver_options.parameter_tolerance = 1e-14;
  solver_options.gradient_tolerance = 0.0;
  solver_options.num_threads = 1;  // deterministic
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);

  GalvoLaserCalibrationResult result;
  result.laser = LaserOf(start, x);
  result.simplified = start;
  result.points = static_cast<int>(points.size());
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.iterations = std::max(0, static_cast<int>(summary.iterations.size()) - 1);
  double sum_sq = 0.0;
  for (const LaserCalibrationPoint& point : points) {
    const std::optional<NearestRay> nearest = FindNearestRay(
        FanOfLaser(result.laser, point.mirror_step), result.laser.viewport, point.p_C);
    const double d = nearest ? nearest->distance_m : std::numeric_limits<double>::infinity();
    sum_sq += d * d;
    result.residual_max_m = std::max(result.residual_max_m, d);
  }
  result.residual_rms_m = std::sqrt(sum_sq / static_cast<double>(points.size()));
  result.std_devs = StdDevs(points, result.laser, options);
  return result;
}

}  // namespace

void GalvoLaserCalibrationOptions::Check() const {
  OptionChecks("GalvoLaserCalibrationOptions").GreaterThan("max_iterations", max_iterations, 0);
}

GalvoLaser SimplifiedGalvoLaser(const std::vector<LaserCalibrationPoint>& points,
                                const GalvoLaser& initial) {
  initial.Check();
  CheckPoints(points, initial, "SimplifiedGalvoLaser");
  GalvoLaser laser = SimplifiedModel(GroupBySteps(points), InAir(initial)).laser;
  laser.viewport = initial.viewport;
  return laser;
}

GalvoLaserCalibrationResult RefineGalvoLaser(const std::vector<LaserCalibrationPoint>& points,
                                             const GalvoLaser& start,
                                             const GalvoLaserCalibrationOptions& options) {
  options.Check();
  start.Check();
  CheckPoints(points, start, "RefineGalvoLaser");
  GalvoLaserCalibrationResult result = Refine(points, InAir(start), options);
  result.laser.viewport = start.viewport;
  result.simplified = start;
  return result;
}

GalvoLaserCalibrationResult CalibrateGalvoLaser(const std::vector<LaserCalibrationPoint>& points,
                                                const GalvoLaser& initial,
                                                const GalvoLaserCalibrationOptions& options) {
  options.Check();
  initial.Check();
  CheckPoints(points, initial, "CalibrateGalvoLaser");
  const PointsByStep by_step = GroupBySteps(points);
  const Simplified simplified = SimplifiedModel(by_step, InAir(initial));
  GalvoLaserCalibrationResult result = Refine(points, simplified.laser, options);
  int iterations = result.iterations;
  // The seed's edge rays again, now reflected on the refined mirror (delta included), then the
  // refinement with that emitter: each pass shrinks the emitter's error ~250 times (what is left
  // of it is what the simplified mirror's delta = 0 put there), so a few passes reach rounding.
  for (int pass = 0; simplified.emitter_from_edge_rays && pass < kEdgeRayPasses; ++pass) {
    const GalvoLaser& laser = result.laser;
    const Eigen::Vector3d o = laser.T_C_L.translation();
    const std::optional<Eigen::Vector3d> emitter =
        EmitterFromEdgeRays(by_step, laser, laser.T_C_L.linear().col(2).dot(o));
    if (!emitter) break;
    GalvoLaser next = laser;
    next.T_C_L.translation() = *emitter;
    result = Refine(points, next, options);
    iterations += result.iterations;
    if ((*emitter - o).norm() <= 1e-11) break;
  }
  result.iterations = iterations;
  result.emitter_from_edge_rays = simplified.emitter_from_edge_rays;
  result.simplified = simplified.laser;
  result.simplified.viewport = initial.viewport;
  result.laser.viewport = initial.viewport;
  return result;
}

std::optional<double> DistanceToFan(const GalvoLaser& laser, int mirror_step,
                                    const Eigen::Vector3d& p_C) {
  const std::optional<NearestRay> nearest =
      FindNearestRay(FanOfLaser(laser, mirror_step), laser.viewport, p_C);
  if (!nearest) return std::nullopt;
  return nearest->distance_m;
}

}  // namespace uwscan::scanner::calibration
