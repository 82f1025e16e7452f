#include "scanner/lasers/galvo_laser.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "scanner/common/option_checks.hpp"
#include "scanner/optics/refraction.hpp"

namespace uwscan::scanner {
namespace {

bool IsRigid(const Eigen::Isometry3d& T) {
  return T.matrix().allFinite() &&
         (T.linear().transpose() * T.linear() - Eigen::Matrix3d::Identity()).norm() < 1e-9 &&
         T.linear().determinant() > 0.0;
}

}  // namespace

RayTrace LaserFan::RayInAir(double fan_tan) const {
  const Eigen::Vector3d d = (central_dir_C + fan_tan * spread_dir_C).normalized();
  const double denom = mirror_normal_C.dot(d);
  if (std::abs(denom) <= 1e-15) return RayTrace{HitStatus::kParallel, Ray{origin_C, d}};
  const double t = (mirror_offset_m - mirror_normal_C.dot(origin_C)) / denom;
  if (t < 0.0) return RayTrace{HitStatus::kBehind, Ray{origin_C, d}};
  return RayTrace{HitStatus::kHit, Ray{origin_C + t * d, Reflect(d, mirror_normal_C)}};
}

RayTrace LaserFan::RayInWater(double fan_tan) const {
  const RayTrace in_air = RayInAir(fan_tan);
  if (!in_air.ok()) return in_air;
  return TraceOut(viewport, in_air.ray);
}

void GalvoLaser::Check() const {
  const OptionChecks check("GalvoLaser");
  check.Require(IsRigid(T_C_L), "T_C_L", "a rigid transform");
  check.Require(IsRigid(T_C_M), "T_C_M", "a rigid transform");
  check.Require(mirror_step_rad != 0.0 && std::abs(mirror_step_rad) < 0.1, "mirror_step_rad",
                "non-zero and below 0.1 rad in magnitude", mirror_step_rad);
  check.Require(std::abs(rotation_distance_m) < 0.1, "rotation_distance_m",
                "below 0.1 m in magnitude", rotation_distance_m);
  check.Require(aperture_rad > 0.0 && aperture_rad < 0.9 * std::numbers::pi, "aperture_rad",
                "in (0, 0.9 pi) rad", aperture_rad);
  check.Require(step_min <= step_max, "step_min", "<= step_max (" + std::to_string(step_max) + ")",
                step_min);
  viewport.Check();
}

double GalvoLaser::MaxFanTan() const { return std::tan(0.5 * aperture_rad); }

LaserFan GalvoLaser::FanAt(double mirror_angle_rad) const {
  const Eigen::Vector3d normal_M(std::sin(mirror_angle_rad), 0.0, std::cos(mirror_angle_rad));
  LaserFan fan;
  fan.origin_C = T_C_L.translation();
  fan.central_dir_C = T_C_L.linear().col(0);
  fan.spread_dir_C = T_C_L.linear().col(1);
  fan.mirror_normal_C = T_C_M.linear() * normal_M;
  fan.mirror_offset_m = fan.mirror_normal_C.dot(T_C_M.translation()) + rotation_distance_m;
  fan.viewport = viewport;
  return fan;
}

}  // namespace uwscan::scanner
