#pragma once

#include "scanner/lasers/mems_laser.hpp"
#include "scanner/lasers/mirror_dynamics.hpp"
#include "scanner/lasers/projection_functions.hpp"
#include "scanner/optics/refractive_camera.hpp"

namespace uwscan::scanner {

// The 2-axis MEMS scanner of seed 001: a camera behind its viewport, the true MEMS laser
// (what the simulator traces), its mirror dynamics, and the projection functions f1..f6 that
// the scanner itself uses (from a calibration, or fitted to the true laser when the file
// gives none), all in the camera frame {C}. Read from a scanner file as a Scanner
// (scanner_file.hpp).
struct MemsScannerModel {
  RefractiveCamera camera;
  MemsLaser laser;
  MirrorDynamicsOptions dynamics;
  ProjectionFunctions functions;
  // True when f1..f6 came from the file (a calibration); false when they were fitted to the
  // true laser, which FitFunctionsToLaser() repeats after the laser (or its viewport) changes.
  bool functions_from_file = false;

  // functions = SampleProjectionFunctions(laser); functions_from_file = false.
  void FitFunctionsToLaser();
  void Check() const;
};

// The scanner shipped in data/scanners/mems_default.yaml, compiled into the library.
MemsScannerModel DefaultMemsScannerModel();

}  // namespace uwscan::scanner
