#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "scanner/lasers/projection_functions.hpp"
#include "scanner/lasers/scan_pattern.hpp"
#include "scanner/lasers/scanner.hpp"
#include "scanner/triangulation/triangulator.hpp"

namespace uwscan::scanner {

struct TriangulatorBuildOptions {
  // Folder where the galvanometer's cone table is kept between runs (light_surface_cache.hpp);
  // empty: fitted every time. Ray-plane fits planes only, which takes milliseconds.
  std::filesystem::path table_cache;
  // MEMS: the projection functions the scan pattern was designed and driven with when the frames
  // were taken (a dive log's own scanner), when the scanner given is another calibration of it.
  // Its lines are where those put them, at their voltages; the scanner given says where those
  // voltages send the beam. std::nullopt: the scanner given designed them.
  std::optional<ProjectionFunctions> driven_with;
};

// Builds the triangulator of `method` for a scanner (galvanometer or MEMS) and its scan
// pattern, with every per-calibration table (camera rays, a plane and a cone per mirror step,
// a plane per MEMS line) computed here, once. The MEMS scanner triangulates with the planes of
// its lines only (seed 001); other methods are an error naming the method.
std::unique_ptr<Triangulator> MakeTriangulator(const Scanner& scanner, const ScanPattern& pattern,
                                               TriangulationMethod method,
                                               const TriangulatorBuildOptions& options = {});

// The method used when none is asked for: ray-cone for the galvanometer scanner (exact to
// 0.05 mm at ray-plane speed), ray-plane for the MEMS scanner.
TriangulationMethod DefaultTriangulationMethod(ScannerKind kind);

}  // namespace uwscan::scanner
