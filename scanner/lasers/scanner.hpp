#pragma once

#include <filesystem>
#include <string>
#include <variant>
#include <vector>

#include "scanner/lasers/calibration_record.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"
#include "scanner/lasers/mems_scanner_model.hpp"
#include "scanner/lasers/scan_pattern.hpp"

namespace uwscan::scanner {

// The one in-memory representation of a scanner: a galvanometer scanner (seed 000) or a MEMS
// scanner (seed 001), each with its camera and viewports in {C}, and the record of how it was
// calibrated. It is read once where it enters (a scanner or calibration file, a dive log's
// header) and then handed as a value to the triangulator factory, the simulator, calibration
// and reconstruction; YAML is only its file format (scanner_file.hpp).
struct Scanner {
  std::variant<GalvoScannerModel, MemsScannerModel> model;
  std::vector<StepRecord> calibration;  // in file order; empty for CAD values

  ScannerKind kind() const;
  const RefractiveCamera& camera() const;
  RefractiveCamera& camera();
  const FlatViewport& laser_viewport() const;
  FlatViewport& laser_viewport();
  // The model of one kind; asking a scanner of the other kind throws uwscan::Error saying so.
  const GalvoScannerModel& galvo() const;
  GalvoScannerModel& galvo();
  const MemsScannerModel& mems() const;
  MemsScannerModel& mems();

  void Check() const;
};

// The top-level sections of a scanner file of `kind` that hold optics (data/README.md):
// camera, camera_viewport, laser or mems, laser_viewport, and for MEMS projection_functions.
std::vector<std::string> ScannerSections(ScannerKind kind);

// Replaces `section` (one of ScannerSections) of *to with that of `from`, a scanner of the same
// kind. Throws uwscan::Error naming the section when it is not one of them, the kinds differ, or
// `from` has no projection functions of its own (only ones fitted to its laser) to give.
void CopySection(const Scanner& from, const std::string& section, Scanner* to);

// After a MEMS scanner's laser or laser viewport changed: projection functions that were fitted
// to the laser are fitted again (as reading the file again would); calibrated ones stay. Does
// nothing for a galvanometer scanner.
void RefitSampledFunctions(Scanner* scanner);

// Adds the record of record.step, replacing an earlier record of the same step in place.
void SetStepRecord(Scanner* scanner, const StepRecord& record);

}  // namespace uwscan::scanner
