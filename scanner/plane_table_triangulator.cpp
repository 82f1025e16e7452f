#include "scanner/plane_table_triangulator.hpp"

#include <cassert>
#include <cmath>
#include <string>

#include "scanner/error.hpp"

namespace uwscan::scanner {
namespace {

// How many peaks ahead the camera-ray table is prefetched (as in RayPlaneTriangulator).
constexpr std::size_t kPrefetchAhead = 8;

}  // namespace

PlaneTableTriangulator::PlaneTableTriangulator(std::shared_ptr<const CameraRayTable> rays,
                                               std::vector<Plane> planes_C,
                                               const TriangulationOptions& options)
    : rays_(std::move(rays)),
      planes_C_(std::move(planes_C)),
      min_sin2_angle_(std::pow(std::sin(options.min_angle_rad), 2)) {
  options.Check();
  if (!rays_) throw Error("plane-table triangulator: missing camera ray table");
  for (std::size_t i = 0; i < planes_C_.size(); ++i) {
    const Plane& plane = planes_C_[i];
    if (!(plane.normal.allFinite() && std::abs(plane.normal.norm() - 1.0) < 1e-9 &&
          std::isfinite(plane.offset_m))) {
      throw Error("plane-table triangulator: plane " + std::to_string(i) +
                  " needs a finite unit normal and a finite offset_m");
    }
  }
}

void PlaneTableTriangulator::TriangulateFrame(int mirror_step,
                                              std::span<const Eigen::Vector2d> peaks_px,
                                              std::span<TriangulatedPoint> out) const {
  assert(out.size() == peaks_px.size());
  if (mirror_step < 0 || static_cast<std::size_t>(mirror_step) >= planes_C_.size()) {
    for (TriangulatedPoint& p : out) {
      p = TriangulatedPoint{Eigen::Vector3d::Zero(), HitStatus::kOutsideSurface};
    }
    return;
  }
  const Plane& plane = planes_C_[static_cast<std::size_t>(mirror_step)];
  const Eigen::Vector3d n = plane.normal;
  const double offset = plane.offset_m;
  Ray ray;
  for (std::size_t i = 0; i < peaks_px.size(); ++i) {
    if (i + kPrefetchAhead < peaks_px.size()) {
      rays_->Prefetch(peaks_px[i + kPrefetchAhead].x(), peaks_px[i + kPrefetchAhead].y());
    }
    TriangulatedPoint& result = out[i];
    result.p_C.setZero();  // misses carry no point
    if (!rays_->Lookup(peaks_px[i].x(), peaks_px[i].y(), &ray)) {
      result.status = HitStatus::kNoIntersection;
      continue;
    }
    const double denom = n.dot(ray.direction);
    const double t = (offset - n.dot(ray.origin)) / denom;
    // Grazing rays: |cos| of the angle to the normal below sin(min_angle) * |d|.
    if (denom * denom <= min_sin2_angle_ * ray.direction.squaredNorm()) {
      result.status = HitStatus::kParallel;
    } else if (t < 0.0) {
      result.status = HitStatus::kBehind;
    } else {
      result.p_C = ray.origin + t * ray.direction;
      result.status = HitStatus::kHit;
    }
  }
}

}  // namespace uwscan::scanner
