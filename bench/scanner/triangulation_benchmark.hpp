#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "bench/progress.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"
#include "scanner/triangulation/light_surface_table.hpp"
#include "scanner/triangulation/triangulator.hpp"

namespace uwscan::bench {

// What accuracy costs in time: the same stripe pixels triangulated by ray-plane, ray-cone and
// exact ray-ray on one core. Each frame is a random mirror step whose fan lights a smooth
// random surface somewhere in the depth range; its exact points are projected exactly through
// the camera viewport into up to `points_per_frame` stripe peaks, sorted as a detector emits
// them (row by row), as a scanner delivers them.
struct TriangulationBenchOptions {
  std::int64_t points = 1'000'000;
  int points_per_frame = 1000;
  double depth_min_m = 0.5;  // seed's working range
  double depth_max_m = 1.5;
  std::uint64_t seed = 1;
  // Passes of each table method and of the limit, interleaved; the fastest of each is reported.
  int repeats = 20;
  int exact_repeats = 3;  // passes of exact ray-ray, the reference (about 20x slower)
  int sweep_repeats = 5;  // passes of each method at each swept table resolution
  int camera_grid_px = 4;
  scanner::LightSurfaceTableOptions surfaces;
  // Table resolutions to sweep, one table at a time (the other at its default), on the same
  // pixels: camera-ray table spacings (px) and rays sampled per fan for the plane/cone fits.
  // Empty: no sweep.
  std::vector<int> sweep_camera_grid_px;
  std::vector<int> sweep_rays_per_fan;

  void Check() const;
};

struct MethodFigures {
  double seconds = 0.0;  // triangulation time only, one core, fastest pass
  double points_per_s = 0.0;
  std::int64_t triangulated = 0;  // points with a result
  // Against exact ray-ray on the points both produced.
  double mean_err_m = 0.0;
  double std_err_m = 0.0;
  double max_err_m = 0.0;
  double fraction_of_limit = 0.0;  // points_per_s / TriangulationBenchResult::limit_points_per_s
};

// One table resolution of the sweep: what building the table took and what the table methods
// then give (errors against exact ray-ray on the same pixels).
struct TableResolutionRow {
  std::string table;  // "camera_rays" (value: grid spacing, px) or "light_surfaces" (rays per fan)
  int value = 0;
  double setup_s = 0.0;  // building this table
  MethodFigures ray_plane, ray_cone;
};

struct TriangulationBenchResult {
  std::int64_t points = 0;
  double setup_s = 0.0;               // tables: camera rays, plane and cone fits per step
  double exact_vs_truth_max_m = 0.0;  // ray-ray against the generating points
  std::map<std::string, MethodFigures> methods;  // keyed by ToString(method)
  // The floor of any table method on the same pixels in the same run: per peak the camera-ray
  // table lookup (prefetched) and one multiply-add per coordinate.
  double limit_seconds = 0.0;
  double limit_points_per_s = 0.0;
  std::vector<TableResolutionRow> resolution;  // the sweep, when asked
};

TriangulationBenchResult RunTriangulationBenchmark(const scanner::GalvoScannerModel& model,
                                                   const TriangulationBenchOptions& options,
                                                   const Progress& progress = {});

}  // namespace uwscan::bench
