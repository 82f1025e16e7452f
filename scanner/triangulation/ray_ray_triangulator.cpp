#include "scanner/triangulation/ray_ray_triangulator.hpp"

#include <cassert>
#include <cmath>

#include "scanner/common/error.hpp"

namespace uwscan::scanner {
namespace {

// Longest common perpendicular, per metre of range, accepted as "the rays meet"; converged
// solves leave ~1e-12 m.
constexpr double kMaxGapM = 1e-9;

// Signed distance between the lines, times the sine of their angle: zero where the laser
// ray crosses the camera ray, changing sign as the fan sweeps across it.
double CrossingFunction(const Eigen::Vector3d& o_s, const Eigen::Vector3d& d_s, const Ray& cam) {
  return (o_s - cam.origin).dot(d_s.cross(cam.direction));
}

// Closest approach of two lines with unit directions; kParallel below the minimum angle. The
// lines must actually meet: a common perpendicular longer than round-off (the root search did
// not converge) is kNoIntersection, never a point.
TriangulatedPoint MidpointOfCommonPerpendicular(const Ray& cam, const Ray& laser,
                                                double min_sin2_angle) {
  const Eigen::Vector3d w = cam.origin - laser.origin;
  const double b = cam.direction.dot(laser.direction);
  const double d = cam.direction.dot(w);
  const double e = laser.direction.dot(w);
  const double sin2 = 1.0 - b * b;
  if (sin2 <= min_sin2_angle)
    return TriangulatedPoint{Eigen::Vector3d::Zero(), HitStatus::kParallel};
  const double t_cam = (b * e - d) / sin2;
  const double t_laser = (e - b * d) / sin2;
  if (t_cam < 0.0 || t_laser < 0.0) {
    return TriangulatedPoint{Eigen::Vector3d::Zero(), HitStatus::kBehind};
  }
  const Eigen::Vector3d on_cam = cam.At(t_cam), on_laser = laser.At(t_laser);
  if ((on_cam - on_laser).norm() > kMaxGapM * (1.0 + on_cam.norm())) {
    return TriangulatedPoint{Eigen::Vector3d::Zero(), HitStatus::kNoIntersection};
  }
  return TriangulatedPoint{0.5 * (on_cam + on_laser), HitStatus::kHit};
}

}  // namespace

RayRayTriangulator::RayRayTriangulator(const GalvoScannerModel& model,
                                       const TriangulationOptions& options, int fan_samples)
    : model_(model) {
  model_.Check();
  options.Check();
  if (fan_samples < 3) throw Error("ray-ray triangulator: fan_samples must be >= 3");
  const double sin_min = std::sin(options.min_angle_rad);
  min_sin2_angle_ = sin_min * sin_min;
  const GalvoLaser& laser = model_.laser;
  const double max_angle = 0.5 * laser.aperture_rad;
  steps_.resize(static_cast<size_t>(laser.step_max - laser.step_min + 1));
  for (int step = laser.step_min; step <= laser.step_max; ++step) {
    StepFan& entry = steps_[static_cast<size_t>(step - laser.step_min)];
    entry.fan = laser.FanAtStep(step);
    for (int k = 0; k < fan_samples; ++k) {
      const double s = std::tan(-max_angle + 2.0 * max_angle * k / (fan_samples - 1));
      const RayTrace trace = entry.fan.RayInWater(s);
      if (trace.ok()) entry.nodes.push_back(FanNode{s, trace.ray.origin, trace.ray.direction});
    }
  }
}

const RayRayTriangulator::StepFan* RayRayTriangulator::FanOf(int step) const {
  if (step < model_.laser.step_min || step > model_.laser.step_max) return nullptr;
  return &steps_[static_cast<size_t>(step - model_.laser.step_min)];
}

TriangulatedPoint RayRayTriangulator::TriangulateRay(int mirror_step, const Ray& cam,
                                                     size_t* bracket_hint) const {
  const StepFan* step = FanOf(mirror_step);
  if (step == nullptr || step->nodes.size() < 2) {
    return TriangulatedPoint{Eigen::Vector3d::Zero(), HitStatus::kOutsideSurface};
  }
  const std::vector<FanNode>& nodes = step->nodes;
  const auto g_node = [&](size_t k) {
    return CrossingFunction(nodes[k].origin, nodes[k].direction, cam);
  };
  const auto exact_node = [&](size_t k) {
    return MidpointOfCommonPerpendicular(cam, Ray{nodes[k].origin, nodes[k].direction},
                                         min_sin2_angle_);
  };

  // Bracket the crossing between two neighbouring table rays: first the hinted interval,
  // else a binary search over the whole fan (whose ends must differ in sign).
  size_t lo = 0, hi = nodes.size() - 1;
  double g_lo = 0.0, g_hi = 0.0;
  bool bracketed = false;
  if (bracket_hint != nullptr && *bracket_hint + 1 < nodes.size()) {
    lo = *bracket_hint, hi = lo + 1;
    g_lo = g_node(lo), g_hi = g_node(hi);
    bracketed = (g_lo > 0.0) != (g_hi > 0.0) || g_lo == 0.0 || g_hi == 0.0;
  }
  if (!bracketed) {
    lo = 0, hi = nodes.size() - 1;
    g_lo = g_node(lo), g_hi = g_node(hi);
    if (g_lo != 0.0 && g_hi != 0.0 && (g_lo > 0.0) == (g_hi > 0.0)) {
      return TriangulatedPoint{Eigen::Vector3d::Zero(), HitStatus::kOutsideSurface};
    }
    while (hi - lo > 1 && g_lo != 0.0 && g_hi != 0.0) {
      const size_t mid = (lo + hi) / 2;
      const double g_mid = g_node(mid);
      if ((g_mid > 0.0) == (g_lo > 0.0)) {
        lo = mid, g_lo = g_mid;
      } else {
        hi = mid, g_hi = g_mid;
      }
    }
  }
  if (bracket_hint != nullptr) *bracket_hint = lo;
  if (g_lo == 0.0) return exact_node(lo);
  if (g_hi == 0.0) return exact_node(hi);

  // Secant iterations on exact traces, kept inside the bracket [s_lo, s_hi] (bisection when
  // a step would leave it). Started from the table's linear interpolation, the secant needs
  // about three traces to reach |ds| <= 1e-15.
  double s_lo = nodes[lo].s, s_hi = nodes[hi].s;
  double s_prev = s_lo, g_prev = g_lo;
  double s = s_lo - g_lo * (s_hi - s_lo) / (g_hi - g_lo);
  Ray laser{nodes[lo].origin, nodes[lo].direction};
  for (int iteration = 0; iteration < 60; ++iteration) {
    const RayTrace trace = step->fan.RayInWater(s);
    if (!trace.ok()) return TriangulatedPoint{Eigen::Vector3d::Zero(), trace.status};
    laser = trace.ray;
    const double g = CrossingFunction(laser.origin, laser.direction, cam);
    if (g == 0.0) break;
    ((g > 0.0) == (g_lo > 0.0) ? s_lo : s_hi) = s;
    double next = s - g * (s - s_prev) / (g - g_prev);
    if (!(next > std::min(s_lo, s_hi) && next < std::max(s_lo, s_hi))) next = 0.5 * (s_lo + s_hi);
    s_prev = s, g_prev = g;
    if (std::abs(next - s) <= 1e-15 * (1.0 + std::abs(s))) break;
    s = next;
  }
  return MidpointOfCommonPerpendicular(cam, laser, min_sin2_angle_);
}

void RayRayTriangulator::TriangulateFrame(int mirror_step,
                                          std::span<const Eigen::Vector2d> peaks_px,
                                          std::span<TriangulatedPoint> out) const {
  assert(out.size() == peaks_px.size());
  size_t bracket_hint = 0;
  for (size_t i = 0; i < peaks_px.size(); ++i) {
    const RayTrace cam = model_.camera.PixelToRayInWater(peaks_px[i]);
    out[i] = cam.ok() ? TriangulateRay(mirror_step, cam.ray, &bracket_hint)
                      : TriangulatedPoint{Eigen::Vector3d::Zero(), cam.status};
  }
}

}  // namespace uwscan::scanner
