#include "scanner/lasers/mems_scanner_model.hpp"

#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::scanner {

void MemsScannerModel::FitFunctionsToLaser() {
  functions = SampleProjectionFunctions(laser);
  functions_from_file = false;
}

void MemsScannerModel::Check() const {
  camera.Check();
  laser.Check();
  dynamics.Check();
  functions.Check();
}

MemsScannerModel DefaultMemsScannerModel() { return DefaultScanner(ScannerKind::kMems).mems(); }

}  // namespace uwscan::scanner
