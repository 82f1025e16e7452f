#include "scanner/sim/stripe_tracer.hpp"

#include <algorithm>
#include <cmath>

namespace uwscan::scanner::sim {
namespace {

// A crossing is accepted when the spot's image lies this close to the line centre.
constexpr double kCrossingTolerancePx = 1e-9;
constexpr int kMaxCrossingIterations = 80;
// Halvings of a sample interval when following the stripe: 2^-40 of a sample step is far below
// a pixel, so an edge is found to well within its row.
constexpr int kMaxFollowDepth = 40;

double LineCoordinate(const Eigen::Vector2d& px, StripeAxis axis) {
  return axis == StripeAxis::kRows ? px.y() : px.x();
}

// Largest squared normalised radius the camera images, with a margin: farther out the
// distortion polynomial may fold back into the image and would put spots where none can be.
double MaxNormalisedRadius2(const PinholeCamera& camera) {
  double r2 = 0.0;
  const double w = camera.width_px - 0.5;
  const double h = camera.height_px - 0.5;
  for (const Eigen::Vector2d& corner : {Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(w, -0.5),
                                        Eigen::Vector2d(-0.5, h), Eigen::Vector2d(w, h)}) {
    const std::optional<Eigen::Vector2d> xy = camera.Undistort(corner);
    if (xy) r2 = std::max(r2, xy->squaredNorm());
  }
  // No corner inverts (an extreme distortion): fall back to the pinhole extent.
  if (r2 == 0.0) {
    const double x = std::max(camera.cx_px, w - camera.cx_px) / camera.fx_px;
    const double y = std::max(camera.cy_px, h - camera.cy_px) / camera.fy_px;
    r2 = x * x + y * y;
  }
  return r2 * 1.1 * 1.1;
}

}  // namespace

StripeTracer::StripeTracer(const RefractiveCamera& camera, const RayCaster& caster,
                           const StripeTraceOptions& options)
    : camera_(camera),
      caster_(caster),
      options_(options),
      max_normalised_radius2_(MaxNormalisedRadius2(camera.camera)) {}

bool StripeTracer::Visible(const TracedPeak& spot, const Eigen::Vector3d& laser_origin_W,
                           const Eigen::Vector3d& camera_exit_W) const {
  // A back face: the laser lights one side of the surface, the camera looks at the other.
  const double laser_side = spot.normal_W.dot(laser_origin_W - spot.p_W);
  const double camera_side = spot.normal_W.dot(camera_exit_W - spot.p_W);
  if (laser_side * camera_side <= 0.0) return false;
  return !caster_.Blocked(spot.p_W, camera_exit_W);
}

std::optional<TracedPeak> StripeTracer::SpotAt(const LaserPath& path,
                                               const Eigen::Isometry3d& T_W_C, double s) const {
  const RayTrace laser = path.ray_in_water_C(s);
  if (!laser.ok()) return std::nullopt;
  const Ray ray_W{T_W_C * laser.ray.origin, T_W_C.linear() * laser.ray.direction};
  const std::optional<SurfaceHit> hit = caster_.Cast(ray_W);
  if (!hit) return std::nullopt;

  const Eigen::Vector3d p_C = T_W_C.inverse() * hit->point_W;
  const DirectionResult in_air =
      DirectionThroughViewport(camera_.viewport, Eigen::Vector3d::Zero(), p_C);
  if (!in_air.ok() || !(in_air.direction.z() > 1e-9)) return std::nullopt;
  const Eigen::Vector2d xy = in_air.direction.head<2>() / in_air.direction.z();
  if (xy.squaredNorm() > max_normalised_radius2_) return std::nullopt;
  const Eigen::Vector2d px = camera_.camera.Project(in_air.direction);
  if (!camera_.camera.InImage(px)) return std::nullopt;
  const RayTrace to_camera =
      TraceOut(camera_.viewport, Ray{Eigen::Vector3d::Zero(), in_air.direction});
  if (!to_camera.ok()) return std::nullopt;

  TracedPeak spot;
  spot.px = px;
  spot.p_W = hit->point_W;
  spot.normal_W = hit->normal_W;
  spot.object_index = hit->object_index;
  spot.reflectance = hit->reflectance;
  spot.laser_range_m = hit->distance_m;
  spot.camera_range_m = (p_C - to_camera.ray.origin).norm();
  spot.cos_incidence = std::abs(hit->normal_W.dot(ray_W.direction.normalized()));
  spot.z_C_m = p_C.z();
  spot.s = s;
  // The camera's ray to the spot leaves its viewport at to_camera's origin.
  if (options_.occlusion && !Visible(spot, ray_W.origin, T_W_C * to_camera.ray.origin)) {
    return std::nullopt;
  }
  return spot;
}

std::optional<TracedPeak> StripeTracer::SolveCrossing(const LaserPath& path,
                                                      const Eigen::Isometry3d& T_W_C,
                                                      const TracedPeak& a, const TracedPeak& b,
                                                      double line) const {
  // Illinois (modified regula falsi) on f(s) = line coordinate of the spot - line: superlinear
  // on a smooth stripe, never leaving the bracket. A spot that vanishes or changes surface
  // inside the bracket means the stripe is cut there: no crossing.
  double s_lo = a.s, s_hi = b.s;
  double f_lo = LineCoordinate(a.px, options_.axis) - line;
  double f_hi = LineCoordinate(b.px, options_.axis) - line;
  if (f_lo == 0.0) return a;
  if (f_hi == 0.0) return b;
  int stale_side = 0;
  for (int iteration = 0; iteration < kMaxCrossingIterations; ++iteration) {
    double s = s_hi - f_hi * (s_hi - s_lo) / (f_hi - f_lo);
    if (!(s > std::min(s_lo, s_hi) && s < std::max(s_lo, s_hi))) s = 0.5 * (s_lo + s_hi);
    if (s == s_lo || s == s_hi) break;  // the bracket cannot shrink further
    const std::optional<TracedPeak> spot = SpotAt(path, T_W_C, s);
    if (!spot || spot->object_index != a.object_index) return std::nullopt;
    const double f = LineCoordinate(spot->px, options_.axis) - line;
    if (std::abs(f) <= kCrossingTolerancePx) return spot;
    if ((f < 0.0) == (f_lo < 0.0)) {
      s_lo = s;
      f_lo = f;
      if (stale_side == -1) f_hi *= 0.5;
      stale_side = -1;
    } else {
      s_hi = s;
      f_hi = f;
      if (stale_side == 1) f_lo *= 0.5;
      stale_side = 1;
    }
  }
  return std::nullopt;
}

bool StripeTracer::Continues(const TracedPeak& a, const TracedPeak& b) const {
  return a.object_index == b.object_index &&
         (a.px - b.px).cwiseAbs().maxCoeff() <= options_.max_jump_px;
}

void StripeTracer::Follow(const LaserPath& path, const Eigen::Isometry3d& T_W_C, double s_a,
                          const std::optional<TracedPeak>& a, double s_b,
                          const std::optional<TracedPeak>& b, int depth,
                          std::vector<TracedPeak>* peaks) const {
  if (!a && !b) return;  // no surface at either end: nothing lit in between at this resolution
  if (a && b && Continues(*a, *b)) return AddCrossings(path, T_W_C, *a, *b, peaks);
  // The ends do not continue each other: the stripe ends, changes surface, or its image moves
  // fast over one surface seen obliquely. Halving the interval until each part is continuous
  // follows the fast image row by row, and at a true cut homes in on the edge, so that no row
  // near an edge is lost and none is counted twice.
  if (depth >= kMaxFollowDepth) return;
  const double s_mid = 0.5 * (s_a + s_b);
  const std::optional<TracedPeak> mid = SpotAt(path, T_W_C, s_mid);
  Follow(path, T_W_C, s_a, a, s_mid, mid, depth + 1, peaks);
  Follow(path, T_W_C, s_mid, mid, s_b, b, depth + 1, peaks);
}

void StripeTracer::AddCrossings(const LaserPath& path, const Eigen::Isometry3d& T_W_C,
                                const TracedPeak& a, const TracedPeak& b,
                                std::vector<TracedPeak>* peaks) const {
  const int line_count =
      options_.axis == StripeAxis::kRows ? camera_.camera.height_px : camera_.camera.width_px;
  const double ca = LineCoordinate(a.px, options_.axis);
  const double cb = LineCoordinate(b.px, options_.axis);
  const double lo = std::min(ca, cb);
  const double hi = std::max(ca, cb);
  if (lo == hi) return;  // the stripe runs along a line centre: no crossing to solve
  // Half-open [lo, hi): a line centre falling exactly on a sample is counted once.
  for (double line = std::max(std::ceil(lo), 0.0); line < hi && line < line_count; ++line) {
    std::optional<TracedPeak> peak = SolveCrossing(path, T_W_C, a, b, line);
    if (!peak) continue;
    // The solve ends within 1e-9 px of the line centre; the peak is put on it exactly.
    (options_.axis == StripeAxis::kRows ? peak->px.y() : peak->px.x()) = line;
    peaks->push_back(*peak);
  }
}

std::vector<TracedPeak> StripeTracer::Trace(const LaserPath& path,
                                            const Eigen::Isometry3d& T_W_C) const {
  const int n = std::max(path.samples, 2);
  std::vector<std::optional<TracedPeak>> samples(static_cast<size_t>(n));
  std::vector<double> s_of(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) {
    s_of[static_cast<size_t>(k)] = path.s_begin + (path.s_end - path.s_begin) * k / (n - 1);
    samples[static_cast<size_t>(k)] = SpotAt(path, T_W_C, s_of[static_cast<size_t>(k)]);
  }

  std::vector<TracedPeak> peaks;
  for (size_t k = 0; k + 1 < samples.size(); ++k) {
    Follow(path, T_W_C, s_of[k], samples[k], s_of[k + 1], samples[k + 1], 0, &peaks);
  }
  const StripeAxis axis = options_.axis;
  const StripeAxis across = axis == StripeAxis::kRows ? StripeAxis::kColumns : StripeAxis::kRows;
  std::sort(peaks.begin(), peaks.end(), [axis, across](const TracedPeak& l, const TracedPeak& r) {
    const double cl = LineCoordinate(l.px, axis), cr = LineCoordinate(r.px, axis);
    if (cl != cr) return cl < cr;
    return LineCoordinate(l.px, across) < LineCoordinate(r.px, across);
  });
  return peaks;
}

}  // namespace uwscan::scanner::sim
