#pragma once

#include <filesystem>
#include <string>

#include "scanner/lasers/galvo_laser.hpp"
#include "scanner/optics/refractive_camera.hpp"

namespace uwscan::scanner {

// A steered-plane laser scanner: a camera behind its viewport and a galvanometer laser behind
// its own viewport, all in the camera frame {C}.
struct ScannerModel {
  RefractiveCamera camera;
  GalvoLaser laser;

  void Check() const;
};

// Reads a scanner from YAML (format documented in data/README.md). Throws uwscan::Error
// naming the source, line and field on anything missing or malformed.
ScannerModel ParseScannerModel(const std::string& yaml_text, const std::string& source_name);
ScannerModel LoadScannerModel(const std::filesystem::path& path);

// The scanner shipped in data/scanners/galvo_default.yaml, compiled into the library.
ScannerModel DefaultScannerModel();

}  // namespace uwscan::scanner
