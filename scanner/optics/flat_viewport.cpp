#include "scanner/optics/flat_viewport.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "scanner/common/option_checks.hpp"
#include "scanner/optics/refraction.hpp"

namespace uwscan::scanner {
namespace {

// Intersects a ray with the plane normal . x = offset; kParallel / kBehind as values. An
// origin on the face to round-off (as the rays returned here start) counts as on it, t = 0.
RayHit HitFace(const Ray& ray, const Eigen::Vector3d& normal, double offset) {
  const double denom = normal.dot(ray.direction);
  if (std::abs(denom) <= 1e-15) return RayHit::Miss(HitStatus::kParallel);
  const double gap = offset - normal.dot(ray.origin);
  const double round_off = 8.0 * std::numeric_limits<double>::epsilon() *
                           (std::abs(offset) + ray.origin.cwiseAbs().sum());
  if (std::abs(gap) <= round_off) return RayHit{HitStatus::kHit, 0.0, ray.origin};
  const double t = gap / denom;
  if (t < 0.0) return RayHit::Miss(HitStatus::kBehind);
  return RayHit{HitStatus::kHit, t, ray.At(t)};
}

// Crosses one face: intersection with the face, then Snell's law into the next medium.
RayTrace CrossFace(const Ray& ray, const Eigen::Vector3d& normal, double offset, double n_from,
                   double n_to) {
  const RayHit hit = HitFace(ray, normal, offset);
  if (!hit.ok()) return RayTrace{hit.status, ray};
  const std::optional<Eigen::Vector3d> refracted = Refract(ray.direction, normal, n_from, n_to);
  if (!refracted) return RayTrace{HitStatus::kTotalInternalReflection, ray};
  return RayTrace{HitStatus::kHit, Ray{hit.point, *refracted}};
}

// In the plane of refraction: the radial reach of the path at the point's depth as a function
// of u = tan(angle in air), and its derivative. In a medium whose sine is k times the air's,
// tan = k u / sqrt(1 + (1 - k^2) u^2). With u (not the sine) as unknown the reach is linear in
// air plus concave terms, so Newton started on the near side converges without overshoot
// even at grazing angles, where the sine would be pinned against 1.
struct Reach {
  double value;
  double derivative;
};
Reach RadialReach(double u, const std::array<double, 3>& lengths,
                  const std::array<double, 3>& ratios) {
  Reach r{0.0, 0.0};
  for (int i = 0; i < 3; ++i) {
    const double k = ratios[i];
    const double w = 1.0 + (1.0 - k * k) * u * u;
    const double root = std::sqrt(w);
    r.value += lengths[i] * k * u / root;
    r.derivative += lengths[i] * k / (w * root);
  }
  return r;
}

}  // namespace

void FlatViewport::Check() const {
  const OptionChecks check("FlatViewport");
  check.Require(normal.allFinite() && std::abs(normal.norm() - 1.0) < 1e-9, "normal",
                "a finite unit vector");
  check.Finite("distance_m", distance_m);
  check.InRange("thickness_m", thickness_m, 0.0, 1.0, Interval::kOpenHigh, "m");
  check.InRange("n_air", n_air, 1.0, 3.0, Interval::kOpenHigh);
  check.Require(n_glass >= n_air && n_glass < 3.0, "n_glass", "in [n_air, 3)", n_glass);
  check.Require(n_water >= n_air && n_water < 3.0, "n_water", "in [n_air, 3)", n_water);
}

RayTrace TraceOut(const FlatViewport& v, const Ray& ray_in_air) {
  // Closed form for parallel faces (this is on every triangulation's hot path): the component
  // of the unit direction along the faces scales by n_air / n_medium in each medium, so the
  // glass only shifts the ray sideways and the water direction follows from air directly.
  const Eigen::Vector3d& n = v.normal;
  const double cos_air = n.dot(ray_in_air.direction);
  if (std::abs(cos_air) <= 1e-15) return RayTrace{HitStatus::kParallel, ray_in_air};
  const double t = (v.distance_m - n.dot(ray_in_air.origin)) / cos_air;
  if (cos_air < 0.0 || t < 0.0) return RayTrace{HitStatus::kBehind, ray_in_air};
  const Eigen::Vector3d along_faces = ray_in_air.direction - cos_air * n;
  const double sin2_air = along_faces.squaredNorm();
  const double eta_glass = v.n_air / v.n_glass, eta_water = v.n_air / v.n_water;
  // n_glass, n_water >= n_air (Check), so neither square root can go negative.
  const double cos_glass = std::sqrt(std::max(0.0, 1.0 - eta_glass * eta_glass * sin2_air));
  const double cos_water = std::sqrt(std::max(0.0, 1.0 - eta_water * eta_water * sin2_air));
  const Eigen::Vector3d exit =
      ray_in_air.At(t) + v.thickness_m * ((eta_glass / cos_glass) * along_faces + n);
  return RayTrace{HitStatus::kHit, Ray{exit, eta_water * along_faces + cos_water * n}};
}

RayTrace TraceIn(const FlatViewport& v, const Ray& ray_in_water) {
  const RayTrace in_glass =
      CrossFace(ray_in_water, v.normal, v.OuterOffset(), v.n_water, v.n_glass);
  if (!in_glass.ok()) return in_glass;
  return CrossFace(in_glass.ray, v.normal, v.distance_m, v.n_glass, v.n_air);
}

DirectionResult DirectionThroughViewport(const FlatViewport& v,
                                         const Eigen::Vector3d& center_in_air,
                                         const Eigen::Vector3d& point_in_water) {
  const Eigen::Vector3d& n = v.normal;
  const double to_inner = v.distance_m - n.dot(center_in_air);
  const Eigen::Vector3d offset = point_in_water - center_in_air;
  const double depth = n.dot(offset);
  const double in_water = depth - to_inner - v.thickness_m;
  if (to_inner < 0.0 || in_water <= 0.0) return DirectionResult{HitStatus::kBehind};

  const Eigen::Vector3d radial = offset - depth * n;
  const double rho = radial.norm();
  // On the axis (to round-off) the path is straight along the normal.
  if (rho <= 1e-15 * depth) return DirectionResult{HitStatus::kHit, n, 0};

  const std::array<double, 3> lengths = {to_inner, v.thickness_m, in_water};
  const std::array<double, 3> ratios = {1.0, v.n_air / v.n_glass, v.n_air / v.n_water};
  // The root lies in [rho / depth, rho / to_inner]: refraction into denser media only
  // steepens the air angle, and the air leg alone must not overshoot. With the centre on the
  // inner face the reach is bounded; then points beyond it cannot be seen (kNoIntersection).
  double lo = rho / depth;
  double hi = to_inner > 0.0 ? rho / to_inner : 1e12;
  double u = lo;
  int iteration = 0;
  for (; iteration < 100; ++iteration) {
    const Reach r = RadialReach(u, lengths, ratios);
    const double f = r.value - rho;
    if (f == 0.0) break;
    (f > 0.0 ? hi : lo) = u;
    double next = u - f / r.derivative;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);  // Newton left the bracket
    const double step = std::abs(next - u);
    u = next;
    if (step <= 2e-16 * u || hi - lo <= 4e-16 * hi) break;
  }
  if (std::abs(RadialReach(u, lengths, ratios).value - rho) > 1e-9 * (rho + depth)) {
    return DirectionResult{HitStatus::kNoIntersection};
  }
  const double cos_air = 1.0 / std::sqrt(1.0 + u * u);
  return DirectionResult{HitStatus::kHit, cos_air * (n + u * (radial / rho)), iteration + 1};
}

}  // namespace uwscan::scanner
