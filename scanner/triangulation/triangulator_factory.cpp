#include "scanner/triangulation/triangulator_factory.hpp"

#include "scanner/common/error.hpp"
#include "scanner/lasers/mems_scan_pattern.hpp"
#include "scanner/optics/camera_ray_table.hpp"
#include "scanner/triangulation/light_surface_cache.hpp"
#include "scanner/triangulation/plane_table_triangulator.hpp"
#include "scanner/triangulation/ray_ray_triangulator.hpp"
#include "scanner/triangulation/surface_triangulators.hpp"

namespace uwscan::scanner {
namespace {

std::unique_ptr<Triangulator> MakeGalvoTriangulator(const GalvoScannerModel& model,
                                                    TriangulationMethod method,
                                                    const TriangulatorBuildOptions& options) {
  if (method == TriangulationMethod::kRayRay) return std::make_unique<RayRayTriangulator>(model);
  auto rays = std::make_shared<const CameraRayTable>(model.camera);
  LightSurfaceTableOptions table;
  if (method == TriangulationMethod::kRayPlane) {
    table.fit_cones = false;
    return std::make_unique<RayPlaneTriangulator>(
        rays, std::make_shared<const LightSurfaceTable>(model.laser, table));
  }
  std::shared_ptr<const LightSurfaceTable> surfaces =
      options.table_cache.empty()
          ? std::make_shared<const LightSurfaceTable>(model.laser, table)
          : LoadOrBuildLightSurfaceTable(model.laser, table, options.table_cache).table;
  return std::make_unique<RayConeTriangulator>(rays, surfaces);
}

std::unique_ptr<Triangulator> MakeMemsTriangulator(
    const MemsScannerModel& model, const MemsScan& scan, TriangulationMethod method,
    const std::optional<ProjectionFunctions>& driven_with) {
  if (method != TriangulationMethod::kRayPlane) {
    throw Error(
        "the MEMS scanner triangulates with the planes of its lines only (seed 001); method '" +
        std::string(ToString(method)) + "' needs a galvanometer scanner");
  }
  MemsScanPatternOptions pattern;
  pattern.lines = scan.lines;
  pattern.waypoints_per_line = scan.waypoints_per_line;
  pattern.fov_fraction_x = scan.fov_fraction_x;
  pattern.fov_fraction_y = scan.fov_fraction_y;
  std::vector<Plane> planes;
  const std::vector<MemsLine> lines =
      DesignMemsScanPattern(driven_with.value_or(model.functions), pattern);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    planes.push_back(driven_with ? MemsLinePlaneAt(model.functions, lines[i].volts,
                                                   pattern.plane_extension_m, static_cast<int>(i))
                                 : lines[i].plane_C);
  }
  return std::make_unique<PlaneTableTriangulator>(
      std::make_shared<const CameraRayTable>(model.camera), std::move(planes));
}

}  // namespace

TriangulationMethod DefaultTriangulationMethod(ScannerKind kind) {
  return kind == ScannerKind::kGalvo ? TriangulationMethod::kRayCone
                                     : TriangulationMethod::kRayPlane;
}

std::unique_ptr<Triangulator> MakeTriangulator(const Scanner& scanner, const ScanPattern& pattern,
                                               TriangulationMethod method,
                                               const TriangulatorBuildOptions& options) {
  pattern.Check();
  if (pattern.kind != scanner.kind()) {
    throw Error(std::string("the scan pattern is for a ") + ToString(pattern.kind) +
                " scanner, the scanner is " + ToString(scanner.kind()));
  }
  if (pattern.kind == ScannerKind::kGalvo)
    return MakeGalvoTriangulator(scanner.galvo(), method, options);
  return MakeMemsTriangulator(scanner.mems(), pattern.mems, method, options.driven_with);
}

}  // namespace uwscan::scanner
