#include "scanner/calibration/laser_viewport_calibration.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "scanner/calibration/jet_geometry.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner::calibration {
namespace {

using jet::Slab;
using jet::TraceOutT;
using jet::Value;
using jet::Vec3;
using Jet1 = ceres::Jet<double, 1>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Signed distance between the camera line and a laser line, times the sine of their angle:
// zero where the fan ray crosses the camera ray (as in RayRayTriangulator).
template <typename T>
T Crossing(const Vec3<T>& laser_origin, const Vec3<T>& laser_direction, const Ray& camera) {
  return (laser_origin - camera.origin.cast<T>())
      .dot(laser_direction.cross(camera.direction.cast<T>()));
}

// The fan ray of tangent s after the mirror (in air) and its derivative in s, analytically.
struct AirRay {
  Eigen::Vector3d origin, direction, d_origin, d_direction;
};
std::optional<AirRay> AirRayAt(const LaserFan& fan, double s) {
  const Eigen::Vector3d raw = fan.central_dir_C + s * fan.spread_dir_C;
  const double length = raw.norm();
  const Eigen::Vector3d d = raw / length;
  const Eigen::Vector3d d_s = (fan.spread_dir_C - d.dot(fan.spread_dir_C) * d) / length;
  const Eigen::Vector3d& m = fan.mirror_normal_C;
  const double m_d = m.dot(d);
  if (!(std::abs(m_d) > 1e-15)) return std::nullopt;
  const double t = (fan.mirror_offset_m - m.dot(fan.origin_C)) / m_d;
  const double t_s = -t * m.dot(d_s) / m_d;
  return AirRay{fan.origin_C + t * d, d - 2.0 * d.dot(m) * m, t_s * d + t * d_s,
                d_s - 2.0 * d_s.dot(m) * m};
}

// The fan ray that meets the camera ray: the root of the crossing function in s by secant
// steps, from the ray aimed at p's mirror image (exact without refraction). The function is
// smooth and monotone across the fan, and this start is within a few 0.01 of the root.
std::optional<double> CrossingTangent(const LaserFan& fan, const Ray& camera,
                                      const Eigen::Vector3d& p) {
  const auto g = [&](double s) -> std::optional<double> {
    const RayTrace ray = fan.RayInWater(s);
    if (!ray.ok()) return std::nullopt;
    return Crossing<double>(ray.ray.origin, ray.ray.direction, camera);
  };
  const Eigen::Vector3d image =
      p - 2.0 * (fan.mirror_normal_C.dot(p) - fan.mirror_offset_m) * fan.mirror_normal_C;
  const double ahead = fan.central_dir_C.dot(image - fan.origin_C);
  double s0 = ahead > 0.0 ? fan.spread_dir_C.dot(image - fan.origin_C) / ahead : 0.0;
  double s1 = s0 + 1e-3;
  std::optional<double> g0 = g(s0), g1 = g(s1);
  for (int iteration = 0; iteration < 60 && g0 && g1; ++iteration) {
    if (*g1 == 0.0) return s1;
    if (*g1 == *g0) return std::nullopt;
    const double s2 = s1 - *g1 * (s1 - s0) / (*g1 - *g0);
    if (!(std::abs(s2) < 4.0)) return std::nullopt;  // beyond 76 degrees: lost
    if (std::abs(s2 - s1) <= 1e-15 * (1.0 + std::abs(s2))) return s2;
    s0 = s1, g0 = g1;
    s1 = s2, g1 = g(s1);
  }
  return std::nullopt;
}

// Unknowns: the tilt (u1, u2) of the normal, n = normalise(n0 + u1 e1 + u2 e2) with e1, e2
// across n0, zero at the start; distance and thickness in metres.
struct Unknowns {
  std::array<double, 2> tilt{};
  std::array<double, 1> distance{};
  std::array<double, 1> thickness{};
};

struct TiltBasis {
  Eigen::Vector3d n0, e1, e2;
  explicit TiltBasis(const Eigen::Vector3d& normal) : n0(normal) {
    const Eigen::Vector3d helper =
        std::abs(n0.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    e1 = n0.cross(helper).normalized();
    e2 = n0.cross(e1);
  }
  template <typename T>
  Vec3<T> Normal(const T* tilt) const {
    return (n0.cast<T>() + tilt[0] * e1.cast<T>() + tilt[1] * e2.cast<T>()).normalized();
  }
};

// Residual of one point: (p+ - p) . d_camera, p+ the ray-ray triangulation through the
// candidate viewport. The crossing s* is found in doubles, then made a function of the unknowns
// by the implicit function theorem: g(s*, theta) = 0 gives ds*/dtheta = -g_theta / g_s, carried
// by the Jet s = s* - (g(s*, theta) - g*) / g_s. The triangulation through the slab with that s
// then has exact derivatives, including the fan ray moving along the fan as the viewport moves.
class ViewportPointCost {
 public:
  ViewportPointCost(const GalvoLaser* laser, const TiltBasis* basis, int step, const Ray& camera,
                    const Eigen::Vector3d& p_C)
      : laser_(laser), basis_(basis), step_(step), camera_(camera), p_C_(p_C) {}

  template <typename T>
  bool operator()(const T* tilt, const T* distance, const T* thickness, T* residual) const {
    const Slab<T> slab{basis_->Normal(tilt), distance[0], thickness[0]};
    LaserFan fan = laser_->FanAtStep(step_);
    fan.viewport.normal = {Value(slab.normal[0]), Value(slab.normal[1]), Value(slab.normal[2])};
    fan.viewport.distance_m = Value(distance[0]);
    fan.viewport.thickness_m = Value(thickness[0]);
    const std::optional<double> s_star = CrossingTangent(fan, camera_, p_C_);
    if (!s_star) return false;
    const std::optional<AirRay> air = AirRayAt(fan, *s_star);
    if (!air) return false;

    // g_s: the crossing's derivative along the fan, the viewport held.
    const Slab<Jet1> held{fan.viewport.normal.cast<Jet1>(), Jet1(fan.viewport.distance_m),
                          Jet1(fan.viewport.thickness_m)};
    const Jet1 ds(0.0, 0);
    Vec3<Jet1> o_j, d_j;
    TraceOutT<Jet1>(held, fan.viewport, air->origin.cast<Jet1>() + ds * air->d_origin.cast<Jet1>(),
                    air->direction.cast<Jet1>() + ds * air->d_direction.cast<Jet1>(), o_j, d_j);
    const double g_s = Crossing<Jet1>(o_j, d_j, camera_).v[0];
    if (!(std::abs(g_s) > 0.0)) return false;

    // s as a function of the unknowns, then the fan ray and the triangulation.
    Vec3<T> o, d;
    TraceOutT<T>(slab, fan.viewport, air->origin.cast<T>(), air->direction.cast<T>(), o, d);
    const T g = Crossing<T>(o, d, camera_);
    const T s_shift = -(g - T(Value(g))) / g_s;  // value 0, derivative ds*/dtheta
    TraceOutT<T>(slab, fan.viewport, air->origin.cast<T>() + s_shift * air->d_origin.cast<T>(),
                 air->direction.cast<T>() + s_shift * air->d_direction.cast<T>(), o, d);
    const Vec3<T> c_o = camera_.origin.cast<T>(), c_d = camera_.direction.cast<T>();
    const Vec3<T> w = c_o - o;
    const T b = c_d.dot(d), dc = c_d.dot(w), e = d.dot(w);
    const T sin2 = T(1.0) - b * b;
    if (!(Value(sin2) > 1e-12)) return false;  // camera and laser rays parallel
    const T t_camera = (b * e - dc) / sin2;
    const T t_laser = (e - b * dc) / sin2;
    const Vec3<T> p_plus = T(0.5) * (c_o + t_camera * c_d + o + t_laser * d);
    residual[0] = (p_plus - p_C_.cast<T>()).dot(c_d);
    return true;
  }

 private:
  const GalvoLaser* laser_;
  const TiltBasis* basis_;
  int step_;
  Ray camera_;
  Eigen::Vector3d p_C_;
};

struct Observation {
  int step;
  Ray camera;
  Eigen::Vector3d p_C;
};

// The problem around `start` (tilt zero there); returns the number of free unknowns.
int BuildProblem(const std::vector<Observation>& observations, const GalvoLaser& laser,
                 const TiltBasis& basis, const FlatViewport& start,
                 const LaserViewportCalibrationOptions& options, Unknowns& x,
                 ceres::Problem& problem) {
  x = Unknowns{};
  x.distance[0] = start.distance_m;
  x.thickness[0] = start.thickness_m;
  for (const Observation& o : observations) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ViewportPointCost, 1, 2, 1, 1>(
                                 new ViewportPointCost(&laser, &basis, o.step, o.camera, o.p_C)),
                             nullptr, x.tilt.data(), x.distance.data(), x.thickness.data());
  }
  if (!options.refine_thickness) {
    problem.SetParameterBlockConstant(x.thickness.data());
    return 3;
  }
  return 4;
}

FlatViewport ViewportOf(const FlatViewport& start, const TiltBasis& basis, const Unknowns& x) {
  FlatViewport v = start;
  v.normal = basis.Normal(x.tilt.data());
  v.distance_m = x.distance[0];
  v.thickness_m = x.thickness[0];
  return v;
}

// Every point whose camera ray leaves the viewport, as an observation. Throws on a point that
// is not finite or whose mirror step is outside the laser's range.
std::vector<Observation> ObservationsOf(const GalvoScannerModel& model,
                                        const std::vector<LaserCalibrationPoint>& points) {
  const GalvoLaser& laser = model.laser;
  std::vector<Observation> observations;
  for (size_t k = 0; k < points.size(); ++k) {
    const LaserCalibrationPoint& point = points[k];
    if (!point.p_C.allFinite() || !point.px.allFinite()) {
      throw Error("CalibrateLaserViewport: point " + std::to_string(k) + " is not finite");
    }
    if (point.mirror_step < laser.step_min || point.mirror_step > laser.step_max) {
      throw Error("CalibrateLaserViewport: point " + std::to_string(k) + " has mirror step " +
                  std::to_string(point.mirror_step) + ", outside the laser's step range");
    }
    const RayTrace camera = model.camera.PixelToRayInWater(point.px);
    if (camera.ok()) observations.push_back(Observation{point.mirror_step, camera.ray, point.p_C});
  }
  return observations;
}

ceres::Solver::Options SolverOptions(const LaserViewportCalibrationOptions& options) {
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = 1e-16;  // exact data must reach rounding
  solver_options.parameter_tolerance = 1e-14;
  solver_options.gradient_tolerance = 0.0;
  solver_options.num_threads = 1;  // deterministic
  solver_options.logging_type = ceres::SILENT;
  return solver_options;
}

// One-sigma standard deviations of the normal's angle, the distance and the thickness; NaN
// when they cannot be computed.
struct Deviations {
  double normal_rad = kNaN;
  double distance_m = kNaN;
  double thickness_m = kNaN;
};

// From the covariance of the unknowns (the tilts, distance and, when refined, thickness) scaled
// by the residual variance. A held thickness has 0.
Deviations StandardDeviations(ceres::Problem& problem, const Unknowns& y, bool refine_thickness,
                              double variance) {
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.num_threads = 1;
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> blocks = {
      {y.tilt.data(), y.tilt.data()}, {y.distance.data(), y.distance.data()}};
  if (refine_thickness) blocks.emplace_back(y.thickness.data(), y.thickness.data());
  if (!covariance.Compute(blocks, &problem)) return Deviations{};
  double tilt[4], distance = 0.0, thickness = 0.0;
  covariance.GetCovarianceBlock(y.tilt.data(), y.tilt.data(), tilt);
  covariance.GetCovarianceBlock(y.distance.data(), y.distance.data(), &distance);
  if (refine_thickness) {
    covariance.GetCovarianceBlock(y.thickness.data(), y.thickness.data(), &thickness);
  }
  return Deviations{std::sqrt(std::max(0.0, (tilt[0] + tilt[3]) * variance)),
                    std::sqrt(std::max(0.0, distance * variance)),
                    std::sqrt(std::max(0.0, thickness * variance))};
}

// The residuals at the solution and the standard deviations of the unknowns.
struct FitFigures {
  double residual_rms_m = 0.0;
  double residual_max_m = 0.0;
  Deviations deviations;
};

// Residuals and standard deviations around the solution: the problem built again there (tilt
// zero, so the tilts are the normal's angles). Residuals of +infinity when they cannot be
// evaluated.
FitFigures FiguresAtSolution(const std::vector<Observation>& observations, const GalvoLaser& laser,
                             const FlatViewport& solution,
                             const LaserViewportCalibrationOptions& options) {
  const TiltBasis at_solution(solution.normal);
  ceres::Problem problem;
  Unknowns y;
  const int unknowns =
      BuildProblem(observations, laser, at_solution, solution, options, y, problem);
  std::vector<double> residuals;
  double cost = 0.0;
  if (!problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, &residuals, nullptr, nullptr)) {
    const double infinity = std::numeric_limits<double>::infinity();
    return FitFigures{infinity, infinity, Deviations{}};
  }
  double sum_sq = 0.0, max_abs = 0.0;
  for (const double r : residuals) {
    sum_sq += r * r;
    max_abs = std::max(max_abs, std::abs(r));
  }
  const double rms = std::sqrt(sum_sq / static_cast<double>(residuals.size()));
  const int points = static_cast<int>(observations.size());
  const double variance = 2.0 * cost / static_cast<double>(points - unknowns);
  return FitFigures{rms, max_abs,
                    StandardDeviations(problem, y, options.refine_thickness, variance)};
}

}  // namespace

void LaserViewportCalibrationOptions::Check() const {
  OptionChecks("LaserViewportCalibrationOptions").GreaterThan("max_iterations", max_iterations, 0);
}

LaserViewportCalibrationResult CalibrateLaserViewport(
    const GalvoScannerModel& model, const std::vector<LaserCalibrationPoint>& points,
    const LaserViewportCalibrationOptions& options) {
  options.Check();
  model.Check();
  const GalvoLaser& laser = model.laser;
  const std::vector<Observation> observations = ObservationsOf(model, points);

  const FlatViewport& initial = laser.viewport;
  const TiltBasis basis(initial.normal);
  ceres::Problem problem;
  Unknowns x;
  const int unknowns = BuildProblem(observations, laser, basis, initial, options, x, problem);
  if (static_cast<int>(observations.size()) <= unknowns) {
    throw Error("CalibrateLaserViewport: " + std::to_string(observations.size()) +
                " usable points for " + std::to_string(unknowns) + " unknowns");
  }
  ceres::Solver::Summary summary;
  ceres::Solve(SolverOptions(options), &problem, &summary);

  LaserViewportCalibrationResult result;
  result.viewport = ViewportOf(initial, basis, x);
  result.points = static_cast<int>(observations.size());
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.iterations = std::max(0, static_cast<int>(summary.iterations.size()) - 1);
  const FitFigures figures = FiguresAtSolution(observations, laser, result.viewport, options);
  result.residual_rms_m = figures.residual_rms_m;
  result.residual_max_m = figures.residual_max_m;
  result.normal_std_rad = figures.deviations.normal_rad;
  result.distance_std_m = figures.deviations.distance_m;
  result.thickness_std_m = figures.deviations.thickness_m;
  return result;
}

}  // namespace uwscan::scanner::calibration
