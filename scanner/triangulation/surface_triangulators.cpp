#include "scanner/triangulation/surface_triangulators.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/triangulation/cone_batch.hpp"

namespace uwscan::scanner {
namespace {

constexpr size_t kPrefetchAhead = CameraRayTable::kPrefetchAhead;

void MarkAll(std::span<TriangulatedPoint> out, HitStatus status) {
  for (TriangulatedPoint& p : out) p = TriangulatedPoint{Eigen::Vector3d::Zero(), status};
}

}  // namespace

void TriangulationOptions::Check() const {
  OptionChecks("TriangulationOptions")
      .InRange("min_angle_rad", min_angle_rad, 0.0, 1.0, Interval::kOpenHigh, "rad");
}

void TriangulatePeaksOnPlane(const CameraRayTable& rays, const Plane& plane, double min_sin2_angle,
                             std::span<const Eigen::Vector2d> peaks_px,
                             std::span<TriangulatedPoint> out) {
  assert(out.size() == peaks_px.size());
  const Eigen::Vector3d n = plane.normal;
  const double offset = plane.offset_m;
  Ray ray;
  for (size_t i = 0; i < peaks_px.size(); ++i) {
    if (i + kPrefetchAhead < peaks_px.size()) {
      rays.Prefetch(peaks_px[i + kPrefetchAhead].x(), peaks_px[i + kPrefetchAhead].y());
    }
    TriangulatedPoint& result = out[i];
    result.p_C.setZero();  // misses carry no point
    if (!rays.Lookup(peaks_px[i].x(), peaks_px[i].y(), &ray)) {
      result.status = HitStatus::kNoIntersection;
      continue;
    }
    const double denom = n.dot(ray.direction);
    const double t = (offset - n.dot(ray.origin)) / denom;
    // Grazing rays: |cos| of the angle to the normal below sin(min_angle) * |d|.
    if (denom * denom <= min_sin2_angle * ray.direction.squaredNorm()) {
      result.status = HitStatus::kParallel;
    } else if (t < 0.0) {
      result.status = HitStatus::kBehind;
    } else {
      result.p_C = ray.origin + t * ray.direction;
      result.status = HitStatus::kHit;
    }
  }
}

RayPlaneTriangulator::RayPlaneTriangulator(std::shared_ptr<const CameraRayTable> rays,
                                           std::shared_ptr<const LightSurfaceTable> surfaces,
                                           const TriangulationOptions& options)
    : rays_(std::move(rays)),
      surfaces_(std::move(surfaces)),
      min_sin2_angle_(std::pow(std::sin(options.min_angle_rad), 2)) {
  options.Check();
  if (!rays_ || !surfaces_) throw Error("ray-plane triangulator: missing tables");
}

void RayPlaneTriangulator::TriangulateFrame(int mirror_step,
                                            std::span<const Eigen::Vector2d> peaks_px,
                                            std::span<TriangulatedPoint> out) const {
  assert(out.size() == peaks_px.size());
  const LightSurfaces* surface = surfaces_->At(mirror_step);
  if (surface == nullptr) return MarkAll(out, HitStatus::kOutsideSurface);
  TriangulatePeaksOnPlane(*rays_, surface->plane, min_sin2_angle_, peaks_px, out);
}

RayConeTriangulator::RayConeTriangulator(std::shared_ptr<const CameraRayTable> rays,
                                         std::shared_ptr<const LightSurfaceTable> surfaces,
                                         const TriangulationOptions& options)
    : rays_(std::move(rays)),
      surfaces_(std::move(surfaces)),
      min_sin2_angle_(std::pow(std::sin(options.min_angle_rad), 2)) {
  options.Check();
  if (surfaces_ && !surfaces_->has_cones()) {
    throw Error("ray-cone triangulator: the light surface table was built without cones");
  }
  if (!rays_ || !surfaces_) throw Error("ray-cone triangulator: missing tables");
}

void RayConeTriangulator::TriangulateFrame(int mirror_step,
                                           std::span<const Eigen::Vector2d> peaks_px,
                                           std::span<TriangulatedPoint> out) const {
  assert(out.size() == peaks_px.size());
  const LightSurfaces* surface = surfaces_->At(mirror_step);
  if (surface == nullptr) return MarkAll(out, HitStatus::kOutsideSurface);
  const PreparedCone cone = PrepareCone(surface->cone);
  // Blocks of rays through the vectorised intersection; a pixel outside the table gets a ray of
  // zero direction in its lane, which meets nothing, and is reported as a miss.
  RayBlock rays;
  HitBlock hits;
  bool in_image[RayBlock::kSize];
  Ray ray;
  for (size_t start = 0; start < peaks_px.size(); start += RayBlock::kSize) {
    const size_t count = std::min(RayBlock::kSize, peaks_px.size() - start);
    for (size_t lane = 0; lane < RayBlock::kSize; ++lane) {
      const size_t i = start + lane;
      const size_t ahead = i + kPrefetchAhead;
      if (ahead < peaks_px.size()) rays_->Prefetch(peaks_px[ahead].x(), peaks_px[ahead].y());
      in_image[lane] = lane < count && rays_->Lookup(peaks_px[i].x(), peaks_px[i].y(), &ray);
      if (!in_image[lane]) ray.direction.setZero();
      rays.ox[lane] = ray.origin.x(), rays.oy[lane] = ray.origin.y(),
      rays.oz[lane] = ray.origin.z();
      rays.dx[lane] = ray.direction.x(), rays.dy[lane] = ray.direction.y();
      rays.dz[lane] = ray.direction.z();
    }
    IntersectRayConeBlock(cone, rays, min_sin2_angle_, &hits);
    for (size_t lane = 0; lane < count; ++lane) {
      TriangulatedPoint& result = out[start + lane];
      result.status = in_image[lane] ? hits.Status(lane) : HitStatus::kNoIntersection;
      result.p_C = Eigen::Vector3d(hits.x[lane], hits.y[lane], hits.z[lane]);  // 0 for misses
    }
  }
}

}  // namespace uwscan::scanner
