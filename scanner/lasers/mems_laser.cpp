#include "scanner/lasers/mems_laser.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
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

void MemsLaser::Check() const {
  const OptionChecks check("MemsLaser");
  check.Require(emitter_origin_C.allFinite(), "emitter_origin_C", "finite coordinates (metres)");
  check.Require(
      emitter_direction_C.allFinite() && std::abs(emitter_direction_C.norm() - 1.0) < 1e-9,
      "emitter_direction_C", "a finite unit vector");
  check.Require(IsRigid(T_C_M), "T_C_M", "a rigid transform");
  check.Require(IsRigid(T_C_Lens), "T_C_Lens", "a rigid transform");
  check.Positive("max_volts", max_volts, "V");
  for (int axis = 0; axis < 2; ++axis) {
    const std::string index = axis == 0 ? "[0]" : "[1]";
    // 0.35 rad (20 deg) is far beyond any MEMS mirror; it only catches degrees typed as radians.
    check.InRange("max_tilt_rad" + index, max_tilt_rad[axis], 0.0, 0.35, Interval::kOpenLow, "rad");
    check.InRange("saturation" + index, saturation[axis], 0.0, 5.0, Interval::kOpenLow);
  }
  check.InRange("lens_gain", lens_gain, 1.0, 10.0);
  viewport.Check();
  // The whole drive range must reach the water: the projection functions are fitted over it.
  for (const double sx : {-1.0, 0.0, 1.0}) {
    for (const double sy : {-1.0, 0.0, 1.0}) {
      const RayTrace trace = RayInWater(max_volts * Eigen::Vector2d(sx, sy));
      if (trace.ok()) continue;
      check.Fail("max_volts",
                 "every beam of the drive range to reach the water (check the emitter, T_C_M, "
                 "T_C_Lens, lens_gain and the viewport)",
                 "the beam at volts (" + OptionValueText(sx * max_volts) + ", " +
                     OptionValueText(sy * max_volts) + ") does not reach the water (" +
                     ToString(trace.status) + ")");
    }
  }
}

Eigen::Vector2d MemsLaser::TiltFromVolts(const Eigen::Vector2d& volts) const {
  Eigen::Vector2d tilt;
  for (int axis = 0; axis < 2; ++axis) {
    const double s = saturation[axis];
    tilt[axis] = max_tilt_rad[axis] * std::tanh(s * volts[axis] / max_volts) / std::tanh(s);
  }
  return tilt;
}

std::optional<Eigen::Vector2d> MemsLaser::VoltsFromTilt(const Eigen::Vector2d& tilt_rad) const {
  Eigen::Vector2d volts;
  for (int axis = 0; axis < 2; ++axis) {
    const double s = saturation[axis];
    const double fraction = tilt_rad[axis] / max_tilt_rad[axis];  // +-1 at +-max_volts
    // A few ulps of slack so that TiltFromVolts(+-max_volts) inverts.
    if (!(std::abs(fraction) <= 1.0 + 8.0 * std::numeric_limits<double>::epsilon())) {
      return std::nullopt;
    }
    // atanh's argument stays <= tanh(s) < 1, so the inverse is finite and well conditioned
    // everywhere inside the drive range.
    const double clamped = std::clamp(fraction, -1.0, 1.0);
    volts[axis] = max_volts * std::atanh(clamped * std::tanh(s)) / s;
  }
  return volts;
}

Eigen::Vector3d MemsLaser::MirrorNormal_C(const Eigen::Vector2d& tilt_rad) const {
  const double cx = std::cos(tilt_rad.x()), sx = std::sin(tilt_rad.x());
  const double cy = std::cos(tilt_rad.y()), sy = std::sin(tilt_rad.y());
  return T_C_M.linear() * Eigen::Vector3d(sy, -sx * cy, cx * cy);
}

RayTrace MemsLaser::RayAfterMirror(const Eigen::Vector2d& tilt_rad) const {
  const Ray emitted{emitter_origin_C, emitter_direction_C};
  const Eigen::Vector3d n = MirrorNormal_C(tilt_rad);
  const double denom = n.dot(emitter_direction_C);
  if (std::abs(denom) <= 1e-12) return RayTrace{HitStatus::kParallel, emitted};
  const double t = n.dot(T_C_M.translation() - emitter_origin_C) / denom;
  if (t < 0.0) return RayTrace{HitStatus::kBehind, emitted};
  return RayTrace{HitStatus::kHit, Ray{emitted.At(t), Reflect(emitter_direction_C, n)}};
}

RayTrace MemsLaser::RayAfterLens(const Eigen::Vector2d& tilt_rad) const {
  RayTrace reflected = RayAfterMirror(tilt_rad);
  if (!reflected.ok()) return reflected;
  const Eigen::Isometry3d T_Lens_C = T_C_Lens.inverse();
  const Eigen::Vector3d origin_Lens = T_Lens_C * reflected.ray.origin;
  const Eigen::Vector3d d = T_Lens_C.linear() * reflected.ray.direction;
  if (d.z() <= 1e-12) return RayTrace{HitStatus::kParallel, reflected.ray};
  const double t = -origin_Lens.z() / d.z();
  if (t < 0.0) return RayTrace{HitStatus::kBehind, reflected.ray};
  const Eigen::Vector3d crossing_Lens = origin_Lens + t * d;

  // theta from atan2 keeps full relative precision near the axis, where the radial part r is
  // tiny; sin(gain theta) / r then tends to gain without cancellation.
  const double r = std::hypot(d.x(), d.y());
  const double theta = std::atan2(r, d.z());
  const double theta_out = lens_gain * theta;
  if (theta_out >= 0.5 * std::numbers::pi) {
    return RayTrace{HitStatus::kOutsideSurface, reflected.ray};
  }
  const double radial_scale = r > 0.0 ? std::sin(theta_out) / r : lens_gain;
  const Eigen::Vector3d out_Lens(radial_scale * d.x(), radial_scale * d.y(), std::cos(theta_out));
  return RayTrace{HitStatus::kHit,
                  Ray{T_C_Lens * crossing_Lens, (T_C_Lens.linear() * out_Lens).normalized()}};
}

RayTrace MemsLaser::RayInWaterFromTilt(const Eigen::Vector2d& tilt_rad) const {
  RayTrace in_air = RayAfterLens(tilt_rad);
  if (!in_air.ok()) return in_air;
  return TraceOut(viewport, in_air.ray);
}

}  // namespace uwscan::scanner
