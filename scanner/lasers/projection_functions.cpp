#include "scanner/lasers/projection_functions.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner {
namespace {

bool IsRigid(const Eigen::Isometry3d& T) {
  return T.matrix().allFinite() &&
         (T.linear().transpose() * T.linear() - Eigen::Matrix3d::Identity()).norm() < 1e-9 &&
         T.linear().determinant() > 0.0;
}

constexpr const char* kNames[6] = {"f1", "f2", "f3", "f4", "f5", "f6"};

// Fits one function and measures its percent error on the data it was fitted to.
Polynomial2d FitOne(int index, std::span<const Eigen::Vector2d> x, const std::vector<double>& y,
                    int degree, FitErrorStats* stats) {
  const auto [lo, hi] = std::minmax_element(y.begin(), y.end());
  const double range = *hi - *lo;
  if (!(range > 0.0)) {
    throw Error(std::string("projection functions: the target of ") + kNames[index] +
                " does not vary over the data; the calibration samples are degenerate");
  }
  Polynomial2d f;
  try {
    f = Polynomial2d::Fit(x, y, degree);
  } catch (const Error& e) {
    throw Error(std::string("projection functions: ") + kNames[index] + ": " + e.what());
  }
  double sum_percent = 0.0, sum_sq = 0.0;
  *stats = FitErrorStats{};
  for (std::size_t k = 0; k < y.size(); ++k) {
    const double residual = f(x[k]) - y[k];
    const double percent = 100.0 * std::abs(residual) / range;
    stats->max_percent = std::max(stats->max_percent, percent);
    sum_percent += percent;
    sum_sq += residual * residual;
  }
  stats->mean_percent = sum_percent / static_cast<double>(y.size());
  stats->rms_abs = std::sqrt(sum_sq / static_cast<double>(y.size()));
  return f;
}

}  // namespace

void ProjectionFunctions::Check() const {
  const OptionChecks check("ProjectionFunctions");
  check.Require(IsRigid(T_C_P), "T_C_P", "a rigid transform");
  for (int axis = 0; axis < 2; ++axis) {
    const std::string index = axis == 0 ? "[0]" : "[1]";
    check.Require(std::isfinite(volts_min[axis]) && volts_min[axis] < 0.0, "volts_min" + index,
                  "a finite value < 0 V (the drive range must bracket 0 V)", volts_min[axis]);
    check.Require(std::isfinite(volts_max[axis]) && volts_max[axis] > 0.0, "volts_max" + index,
                  "a finite value > 0 V (the drive range must bracket 0 V)", volts_max[axis]);
  }
}

bool ProjectionFunctions::InDriveRange(const Eigen::Vector2d& volts, double tolerance_v) const {
  return (volts.array() >= volts_min.array() - tolerance_v).all() &&
         (volts.array() <= volts_max.array() + tolerance_v).all();
}

RayTrace ProjectionFunctions::RayInWater_P(const Eigen::Vector2d& volts) const {
  const Eigen::Vector3d p(f1(volts), f2(volts), 0.0);
  const double vx = f3(volts), vy = f4(volts);
  const double vz2 = 1.0 - vx * vx - vy * vy;
  if (!(vz2 > 0.0)) return RayTrace{HitStatus::kNoIntersection, Ray{p, Eigen::Vector3d::UnitZ()}};
  return RayTrace{HitStatus::kHit, Ray{p, Eigen::Vector3d(vx, vy, std::sqrt(vz2))}};
}

RayTrace ProjectionFunctions::RayInWater_C(const Eigen::Vector2d& volts) const {
  RayTrace trace = RayInWater_P(volts);
  trace.ray.origin = T_C_P * trace.ray.origin;
  trace.ray.direction = T_C_P.linear() * trace.ray.direction;
  return trace;
}

FovLimits ProjectionFunctions::Fov() const {
  const double x_at_max = f1(Eigen::Vector2d(volts_max.x(), 0.0));
  const double x_at_min = f1(Eigen::Vector2d(volts_min.x(), 0.0));
  const double y_at_max = f2(Eigen::Vector2d(0.0, volts_max.y()));
  const double y_at_min = f2(Eigen::Vector2d(0.0, volts_min.y()));
  // Sorted: which voltage sign moves the beam which way depends on how the mirror is mounted.
  FovLimits fov;
  fov.p_min_m = Eigen::Vector2d(std::min(x_at_min, x_at_max), std::min(y_at_min, y_at_max));
  fov.p_max_m = Eigen::Vector2d(std::max(x_at_min, x_at_max), std::max(y_at_min, y_at_max));
  return fov;
}

ProjectionFunctionFit FitProjectionFunctions(std::span<const Eigen::Vector2d> volts,
                                             std::span<const Eigen::Vector2d> p_P,
                                             std::span<const Eigen::Vector3d> v_P,
                                             const Eigen::Isometry3d& T_C_P, int degree) {
  if (p_P.size() != volts.size() || v_P.size() != volts.size()) {
    throw Error("projection functions: " + std::to_string(volts.size()) + " voltage pairs, " +
                std::to_string(p_P.size()) + " points and " + std::to_string(v_P.size()) +
                " directions; they must match");
  }
  const std::size_t n = volts.size();
  std::vector<double> targets[6];
  for (auto& t : targets) t.reserve(n);
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (std::size_t k = 0; k < n; ++k) {
    if (!(v_P[k].allFinite() && std::abs(v_P[k].norm() - 1.0) < 1e-6 && v_P[k].z() > 0.0)) {
      std::ostringstream message;
      message << "projection functions: direction " << k << " (" << v_P[k].transpose()
              << ") must be a unit vector with positive z_P (along the beam at zero volts)";
      throw Error(message.str());
    }
    targets[0].push_back(p_P[k].x());
    targets[1].push_back(p_P[k].y());
    targets[2].push_back(v_P[k].x());
    targets[3].push_back(v_P[k].y());
    targets[4].push_back(volts[k].x());
    targets[5].push_back(volts[k].y());
    lo = lo.cwiseMin(volts[k]);
    hi = hi.cwiseMax(volts[k]);
  }
  ProjectionFunctionFit fit;
  ProjectionFunctions& f = fit.functions;
  f.T_C_P = T_C_P;
  f.volts_min = lo;
  f.volts_max = hi;
  f.f1 = FitOne(0, volts, targets[0], degree, &fit.errors[0]);
  f.f2 = FitOne(1, volts, targets[1], degree, &fit.errors[1]);
  f.f3 = FitOne(2, volts, targets[2], degree, &fit.errors[2]);
  f.f4 = FitOne(3, volts, targets[3], degree, &fit.errors[3]);
  f.f5 = FitOne(4, p_P, targets[4], degree, &fit.errors[4]);
  f.f6 = FitOne(5, p_P, targets[5], degree, &fit.errors[5]);
  f.Check();
  return fit;
}

Eigen::Isometry3d ProjectionPlaneOf(const MemsLaser& laser, double distance_m) {
  const RayTrace centre = laser.RayInWater(Eigen::Vector2d::Zero());
  if (!centre.ok()) {
    throw Error(std::string("projection plane: the beam at zero volts does not reach the water (") +
                ToString(centre.status) + ")");
  }
  const Eigen::Vector3d z = centre.ray.direction.normalized();
  const Eigen::Vector3d x_raw = Eigen::Vector3d::UnitX() - z.x() * z;
  if (!(x_raw.norm() > 1e-6)) {
    throw Error("projection plane: the beam at zero volts runs along x_C; no vertical lines");
  }
  const Eigen::Vector3d x = x_raw.normalized();
  Eigen::Isometry3d T_C_P = Eigen::Isometry3d::Identity();
  T_C_P.linear().col(0) = x;
  T_C_P.linear().col(1) = z.cross(x);
  T_C_P.linear().col(2) = z;
  T_C_P.translation() = centre.ray.origin + distance_m * z;
  return T_C_P;
}

ProjectionSamples SampleLaserRays(const MemsLaser& laser, int grid, double plane_distance_m) {
  if (grid < 2)
    throw Error("projection samples: grid must be at least 2, got " + std::to_string(grid));
  ProjectionSamples samples;
  samples.T_C_P = ProjectionPlaneOf(laser, plane_distance_m);
  const Eigen::Isometry3d T_P_C = samples.T_C_P.inverse();
  const std::size_t count = static_cast<std::size_t>(grid) * static_cast<std::size_t>(grid);
  samples.volts.reserve(count);
  samples.p_P.reserve(count);
  samples.v_P.reserve(count);
  for (int i = 0; i < grid; ++i) {
    for (int j = 0; j < grid; ++j) {
      // Symmetric about zero by construction, so 0 V is a grid node when grid is odd.
      const Eigen::Vector2d volts = laser.max_volts *
                                    Eigen::Vector2d(2.0 * i - (grid - 1), 2.0 * j - (grid - 1)) /
                                    static_cast<double>(grid - 1);
      const RayTrace trace = laser.RayInWater(volts);
      if (!trace.ok()) {
        std::ostringstream message;
        message << "projection samples: the beam at volts (" << volts.transpose()
                << ") does not reach the water (" << ToString(trace.status) << ")";
        throw Error(message.str());
      }
      const Eigen::Vector3d o = T_P_C * trace.ray.origin;
      const Eigen::Vector3d d = (T_P_C.linear() * trace.ray.direction).normalized();
      if (!(d.z() > 1e-6)) {
        std::ostringstream message;
        message << "projection samples: the beam at volts (" << volts.transpose()
                << ") does not cross the projection plane forwards";
        throw Error(message.str());
      }
      // The line (not the half-line) meets the plane: {P} may lie on either side of the face.
      const Eigen::Vector3d p = o - (o.z() / d.z()) * d;
      samples.volts.push_back(volts);
      samples.p_P.emplace_back(p.x(), p.y());
      samples.v_P.push_back(d);
    }
  }
  return samples;
}

ProjectionFunctionFit SampleProjectionFunctionsFit(const MemsLaser& laser, int grid,
                                                   double plane_distance_m) {
  return FitProjectionFunctions(SampleLaserRays(laser, grid, plane_distance_m));
}

}  // namespace uwscan::scanner
