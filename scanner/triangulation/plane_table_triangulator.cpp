#include "scanner/triangulation/plane_table_triangulator.hpp"

#include <cassert>
#include <cmath>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::scanner {
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
  TriangulatePeaksOnPlane(*rays_, planes_C_[static_cast<std::size_t>(mirror_step)], min_sin2_angle_,
                          peaks_px, out);
}

}  // namespace uwscan::scanner
