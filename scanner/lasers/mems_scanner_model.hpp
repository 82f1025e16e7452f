#pragma once

#include <filesystem>
#include <string>

#include "scanner/lasers/mems_laser.hpp"
#include "scanner/lasers/mirror_dynamics.hpp"
#include "scanner/lasers/projection_functions.hpp"
#include "scanner/optics/refractive_camera.hpp"

namespace uwscan::scanner {

// The 2-axis MEMS scanner of seed 001: a camera behind its viewport, the true MEMS laser
// (what the simulator traces), its mirror dynamics, and the projection functions f1..f6 that
// the scanner itself uses (from a calibration, or fitted to the true laser when the file
// gives none), all in the camera frame {C}.
struct MemsScannerModel {
  RefractiveCamera camera;
  MemsLaser laser;
  MirrorDynamicsOptions dynamics;
  ProjectionFunctions functions;

  void Check() const;
};

// Reads a MEMS scanner from YAML (format in data/README.md): `camera` and `camera_viewport`
// as in a galvanometer scanner file, `mems` (laser geometry, static response, lens, dynamics),
// `laser_viewport`, and optionally `projection_functions`; without them the functions are
// SampleProjectionFunctions(laser). Throws uwscan::Error naming the source, line and field on
// anything missing, malformed or unknown.
MemsScannerModel ParseMemsScannerModel(const std::string& yaml_text,
                                       const std::string& source_name);
MemsScannerModel LoadMemsScannerModel(const std::filesystem::path& path);

// The scanner shipped in data/scanners/mems_default.yaml, compiled into the library.
MemsScannerModel DefaultMemsScannerModel();

// The `projection_functions:` section (top-level key included) holding `functions` with
// round-trip precision (17 significant digits), ready to append to a MEMS scanner file.
std::string ProjectionFunctionsToYaml(const ProjectionFunctions& functions);

}  // namespace uwscan::scanner
