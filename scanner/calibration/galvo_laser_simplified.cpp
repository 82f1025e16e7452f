#include "scanner/calibration/galvo_laser_simplified.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/optics/ray.hpp"
#include "scanner/optics/refraction.hpp"
#include "scanner/triangulation/light_plane.hpp"

namespace uwscan::scanner::calibration::galvo_simplified {
namespace {

// A 3-D line (unit direction) fitted through points: centroid and principal direction.
Ray FitLine(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  Eigen::MatrixX3d centred(static_cast<Eigen::Index>(points.size()), 3);
  for (size_t k = 0; k < points.size(); ++k) {
    centred.row(static_cast<Eigen::Index>(k)) = (points[k] - centroid).transpose();
  }
  const Eigen::JacobiSVD<Eigen::MatrixX3d> svd(centred, Eigen::ComputeFullV);
  return Ray{centroid, svd.matrixV().col(0)};
}

constexpr const char* kWho = "SimplifiedGalvoLaser";

// One plane per mirror step, in step order.
struct StepPlanes {
  std::vector<int> steps;
  std::vector<Plane> planes;
};

// Each step's plane fitted to its points, its normal oriented as the CAD's reflected
// laser-plane normal.
StepPlanes FitStepPlanes(const PointsByStep& by_step, const GalvoLaser& initial) {
  const Eigen::Matrix3d R_L_cad = initial.T_C_L.linear();
  StepPlanes fitted;
  for (const auto& [step, step_points] : by_step) {
    std::vector<Eigen::Vector3d> xyz;
    for (const LaserCalibrationPoint* point : step_points) xyz.push_back(point->p_C);
    Plane plane;
    try {
      plane = FitPlane(xyz).plane;
    } catch (const Error& e) {
      throw Error(std::string(kWho) + ": mirror step " + std::to_string(step) + ": " + e.what() +
                  " (a step needs stripes on two projection planes or more)");
    }
    const Eigen::Vector3d cad_normal =
        Reflect(R_L_cad.col(2), initial.FanAtStep(step).mirror_normal_C);
    if (plane.normal.dot(cad_normal) < 0.0) plane = Plane{-plane.normal, -plane.offset_m};
    fitted.steps.push_back(step);
    fitted.planes.push_back(plane);
  }
  return fitted;
}

std::vector<Eigen::Vector3d> NormalsOf(const std::vector<Plane>& planes) {
  std::vector<Eigen::Vector3d> normals(planes.size());
  for (size_t j = 0; j < planes.size(); ++j) normals[j] = planes[j].normal;
  return normals;
}

// The reflected normals turn about the axis a by twice the mirror angle: they lie on a circle
// of the unit sphere, a . n_j = cos(cone angle), i.e. on a plane whose normal is a. On a short
// arc that circle's curvature cannot tell a tilted cone from a great circle; then the plane is
// taken through the origin (the laser plane contains the axis direction, as designs intend).
// Oriented as the CAD mirror's axis (its y).
Eigen::Vector3d MirrorAxis(const std::vector<Eigen::Vector3d>& normals,
                           const Eigen::Matrix3d& R_M_cad) {
  const size_t n = normals.size();
  Eigen::Vector3d axis;
  const double arc = std::acos(std::clamp(normals.front().dot(normals.back()), -1.0, 1.0));
  if (arc >= 0.35) {
    axis = FitPlane(normals).plane.normal;
  } else {
    Eigen::MatrixX3d stacked(static_cast<Eigen::Index>(n), 3);
    for (size_t j = 0; j < n; ++j)
      stacked.row(static_cast<Eigen::Index>(j)) = normals[j].transpose();
    axis = Eigen::JacobiSVD<Eigen::MatrixX3d>(stacked, Eigen::ComputeFullV).matrixV().col(2);
  }
  if (axis.dot(R_M_cad.col(1)) < 0.0) axis = -axis;
  return axis;
}

// The mirror axis and two directions across it, e1 towards the first step's normal.
struct AxisFrame {
  Eigen::Vector3d axis, e1, e2;
};

AxisFrame FrameAbout(const Eigen::Vector3d& axis, const Eigen::Vector3d& first_normal) {
  const Eigen::Vector3d e1 = (first_normal - first_normal.dot(axis) * axis).normalized();
  return AxisFrame{axis, e1, axis.cross(e1)};
}

// The normals' angle about the axis grows by 2 rho_s per step: rho_s from a line fit. Throws
// when it is not a plausible mirror step.
double MirrorStepAngle(const std::vector<int>& steps, const std::vector<Eigen::Vector3d>& normals,
                       const AxisFrame& frame) {
  const size_t n = normals.size();
  std::vector<double> psi(n);
  double mean_step = 0.0, mean_psi = 0.0;
  for (size_t j = 0; j < n; ++j) {
    psi[j] = std::atan2(normals[j].dot(frame.e2), normals[j].dot(frame.e1));
    if (j > 0) psi[j] = psi[j - 1] + std::remainder(psi[j] - psi[j - 1], 2.0 * std::numbers::pi);
    mean_step += steps[j] / static_cast<double>(n);
    mean_psi += psi[j] / static_cast<double>(n);
  }
  double s_xy = 0.0, s_xx = 0.0;
  for (size_t j = 0; j < n; ++j) {
    s_xy += (steps[j] - mean_step) * (psi[j] - mean_psi);
    s_xx += (steps[j] - mean_step) * (steps[j] - mean_step);
  }
  const double rho = 0.5 * s_xy / s_xx;
  if (!(std::abs(rho) > 1e-9 && std::abs(rho) < 0.1)) {
    std::ostringstream message;
    message << kWho << ": the step planes turn by " << 2.0 * rho
            << " rad per step; expected a mirror step in (1e-9, 0.1) rad";
    throw Error(message.str());
  }
  return rho;
}

// With delta = 0 every step plane passes through the axis' point X where it meets pi_l:
// n_j . X = d_j, with n_j . a the same for all j. Unknowns: X across the axis and that
// constant times X's position along it (well conditioned even when the constant is 0).
// Returns X's part across the axis.
Eigen::Vector3d AxisCrossing(const std::vector<Plane>& planes,
                             const std::vector<Eigen::Vector3d>& normals, const AxisFrame& frame) {
  const size_t n = planes.size();
  Eigen::MatrixX3d A(static_cast<Eigen::Index>(n), 3);
  Eigen::VectorXd b(static_cast<Eigen::Index>(n));
  for (size_t j = 0; j < n; ++j) {
    A.row(static_cast<Eigen::Index>(j)) << normals[j].dot(frame.e1), normals[j].dot(frame.e2), 1.0;
    b(static_cast<Eigen::Index>(j)) = planes[j].offset_m;
  }
  const Eigen::Vector3d solution = A.colPivHouseholderQr().solve(b);
  return solution(0) * frame.e1 + solution(1) * frame.e2;
}

// Mirror origin: the point of the axis nearest the CAD's (along the axis is a gauge); zero
// angle: the CAD's normal at angle 0 turned about the axis (see the header).
Eigen::Isometry3d MirrorPose(const GalvoLaser& initial, const AxisFrame& frame,
                             const Eigen::Vector3d& across) {
  const Eigen::Vector3d& axis = frame.axis;
  const Eigen::Matrix3d R_M_cad = initial.T_C_M.linear();
  Eigen::Isometry3d T_C_M = initial.T_C_M;
  const Eigen::Vector3d t_M = across + (initial.T_C_M.translation() - across).dot(axis) * axis;
  const Eigen::Vector3d m0 = (R_M_cad.col(2) - R_M_cad.col(2).dot(axis) * axis).normalized();
  Eigen::Matrix3d R_M;
  R_M << axis.cross(m0), axis, m0;
  T_C_M.linear() = R_M;
  T_C_M.translation() = t_M;
  return T_C_M;
}

struct LaserPlane {
  Eigen::Vector3d normal;
  double offset_m = 0.0;
};

// The laser plane: each step plane reflected back on its mirror plane, averaged; its normal
// oriented as the CAD's.
LaserPlane ReflectedLaserPlane(const GalvoLaser& laser, const StepPlanes& fitted,
                               const Eigen::Vector3d& cad_normal) {
  const size_t n = fitted.planes.size();
  Eigen::Vector3d n_sum = Eigen::Vector3d::Zero();
  double offset_l = 0.0;
  for (size_t j = 0; j < n; ++j) {
    const Plane& plane = fitted.planes[j];
    const LaserFan fan = laser.FanAtStep(fitted.steps[j]);
    const Eigen::Vector3d& m = fan.mirror_normal_C;
    n_sum += Reflect(plane.normal, m);
    offset_l +=
        (plane.offset_m - 2.0 * plane.normal.dot(m) * fan.mirror_offset_m) / static_cast<double>(n);
  }
  Eigen::Vector3d n_l = n_sum.normalized();
  if (n_l.dot(cad_normal) < 0.0) n_l = -n_l, offset_l = -offset_l;
  return LaserPlane{n_l, offset_l};
}

// Laser rotation (seed): z_L = n_l, y_L along pi_l ^ pi_s_0 (s_0: the mirror at angle 0, normal
// m0), x_L = y_L x z_L (the seed's matrix, written right-handed).
Eigen::Matrix3d LaserRotation(const Eigen::Vector3d& n_l, const Eigen::Vector3d& m0,
                              const GalvoLaser& initial) {
  const Eigen::Matrix3d R_L_cad = initial.T_C_L.linear();
  Eigen::Vector3d y_L = n_l.cross(m0);
  if (!(y_L.norm() > 1e-6)) {
    throw Error(std::string(kWho) + ": the laser plane is parallel to the mirror");
  }
  y_L.normalize();
  if (y_L.dot(R_L_cad.col(1)) < 0.0) y_L = -y_L;
  Eigen::Matrix3d R_L;
  R_L << y_L.cross(n_l), y_L, n_l;
  return R_L;
}

}  // namespace

std::optional<Eigen::Vector3d> EmitterFromEdgeRays(const PointsByStep& by_step,
                                                   const GalvoLaser& laser, double offset_l) {
  const Eigen::Vector3d x_L = laser.T_C_L.linear().col(0), y_L = laser.T_C_L.linear().col(1);
  const Eigen::Vector3d n_l = laser.T_C_L.linear().col(2);
  std::vector<Ray> lines;
  for (const auto& [step, points] : by_step) {
    const LaserFan fan = laser.FanAtStep(step);
    const Eigen::Vector3d spread = Reflect(y_L, fan.mirror_normal_C);
    std::map<int, std::pair<Eigen::Vector3d, Eigen::Vector3d>> ends;  // per plane: low, high
    std::map<int, int> count;
    for (const LaserCalibrationPoint* point : points) {
      auto [it, inserted] = ends.try_emplace(point->plane, point->p_C, point->p_C);
      if (!inserted) {
        if (spread.dot(point->p_C) < spread.dot(it->second.first)) it->second.first = point->p_C;
        if (spread.dot(point->p_C) > spread.dot(it->second.second)) it->second.second = point->p_C;
      }
      ++count[point->plane];
    }
    std::vector<Eigen::Vector3d> low, high;
    for (const auto& [plane, end] : ends) {
      if (count[plane] < 2) continue;
      low.push_back(end.first);
      high.push_back(end.second);
    }
    if (low.size() < 2) continue;
    std::array<Ray, 2> edge = {FitLine(low), FitLine(high)};
    for (Ray& ray : edge) {  // pointed back at the mirror, from the far side of the viewport
      if (ray.direction.dot(ray.origin - laser.T_C_M.translation()) > 0.0) {
        ray.direction = -ray.direction;
      }
    }
    const double angle = std::acos(std::clamp(edge[0].direction.dot(edge[1].direction), -1.0, 1.0));
    if (std::abs(angle - laser.aperture_rad) > 0.035) continue;  // 2 degrees: a cut stripe
    for (const Ray& ray : edge) {
      const RayTrace inside = TraceIn(laser.viewport, ray);
      if (!inside.ok()) continue;
      const Eigen::Vector3d& q = inside.ray.origin;
      lines.push_back(
          Ray{q - 2.0 * (fan.mirror_normal_C.dot(q) - fan.mirror_offset_m) * fan.mirror_normal_C,
              Reflect(inside.ray.direction, fan.mirror_normal_C)});
    }
  }
  if (lines.size() < 2) return std::nullopt;
  // Least squares over the plane's two coordinates: sum |P_k (e0 + B z - q_k)|^2.
  const Eigen::Vector3d e0 =
      laser.T_C_L.translation() - (n_l.dot(laser.T_C_L.translation()) - offset_l) * n_l;
  Eigen::Matrix<double, 3, 2> B;
  B << x_L, y_L;
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  for (const Ray& line : lines) {
    const Eigen::Matrix3d P =
        Eigen::Matrix3d::Identity() - line.direction * line.direction.transpose();
    A += B.transpose() * P * B;
    b += B.transpose() * P * (line.origin - e0);
  }
  const Eigen::Vector3d emitter = e0 + B * A.colPivHouseholderQr().solve(b);
  double sum_sq = 0.0;
  for (const Ray& line : lines) {
    const Eigen::Vector3d gap = emitter - line.origin;
    sum_sq += (gap - gap.dot(line.direction) * line.direction).squaredNorm();
  }
  if (!emitter.allFinite() || std::sqrt(sum_sq / static_cast<double>(lines.size())) > 2e-3) {
    return std::nullopt;
  }
  return emitter;
}

PointsByStep GroupBySteps(const std::vector<LaserCalibrationPoint>& points) {
  PointsByStep by_step;
  for (const LaserCalibrationPoint& point : points) by_step[point.mirror_step].push_back(&point);
  return by_step;
}

GalvoLaser InAir(GalvoLaser laser) {
  laser.viewport.n_water = laser.viewport.n_air;
  return laser;
}

Simplified SimplifiedModel(const PointsByStep& by_step, const GalvoLaser& initial) {
  if (by_step.size() < 3) {
    throw Error(std::string(kWho) + ": points of " + std::to_string(by_step.size()) +
                " mirror steps; at least 3 are needed");
  }
  const StepPlanes fitted = FitStepPlanes(by_step, initial);
  const std::vector<Eigen::Vector3d> normals = NormalsOf(fitted.planes);
  const AxisFrame frame = FrameAbout(MirrorAxis(normals, initial.T_C_M.linear()), normals.front());
  GalvoLaser laser = initial;
  laser.mirror_step_rad = MirrorStepAngle(fitted.steps, normals, frame);
  laser.rotation_distance_m = 0.0;
  laser.T_C_M = MirrorPose(initial, frame, AxisCrossing(fitted.planes, normals, frame));

  const LaserPlane plane = ReflectedLaserPlane(laser, fitted, initial.T_C_L.linear().col(2));
  laser.T_C_L.linear() = LaserRotation(plane.normal, laser.T_C_M.linear().col(2), initial);
  // The emitter: the CAD's projected on the laser plane, unless the edge rays place it.
  const Eigen::Vector3d o_cad = initial.T_C_L.translation();
  laser.T_C_L.translation() = o_cad - (plane.normal.dot(o_cad) - plane.offset_m) * plane.normal;
  const std::optional<Eigen::Vector3d> emitter =
      EmitterFromEdgeRays(by_step, laser, plane.offset_m);
  if (emitter) laser.T_C_L.translation() = *emitter;
  laser.Check();
  return Simplified{laser, emitter.has_value()};
}

}  // namespace uwscan::scanner::calibration::galvo_simplified
