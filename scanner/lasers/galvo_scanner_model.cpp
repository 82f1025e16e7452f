#include "scanner/lasers/galvo_scanner_model.hpp"

#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::scanner {

void GalvoScannerModel::Check() const {
  camera.Check();
  laser.Check();
}

GalvoScannerModel DefaultGalvoScannerModel() { return DefaultScanner(ScannerKind::kGalvo).galvo(); }

}  // namespace uwscan::scanner
