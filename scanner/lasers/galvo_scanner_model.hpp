#pragma once

#include "scanner/lasers/galvo_laser.hpp"
#include "scanner/optics/refractive_camera.hpp"

namespace uwscan::scanner {

// A steered-plane laser scanner (seed 000): a camera behind its viewport and a galvanometer
// laser behind its own viewport, all in the camera frame {C}. Read from a scanner file as a
// Scanner (scanner_file.hpp).
struct GalvoScannerModel {
  RefractiveCamera camera;
  GalvoLaser laser;

  void Check() const;
};

// The scanner shipped in data/scanners/galvo_default.yaml, compiled into the library.
GalvoScannerModel DefaultGalvoScannerModel();

}  // namespace uwscan::scanner
