#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "scanner/optics/flat_viewport.hpp"
#include "scanner/lasers/galvo_laser.hpp"
#include "scanner/optics/pinhole_camera.hpp"
#include "scanner/lasers/projection_functions.hpp"

namespace uwscan::scanner::calibration {

// A calibration file is a scanner file (galvanometer or MEMS, data/README.md) whose values are
// the calibrated ones, plus a `calibration:` section recording, per step, where they came
// from: the dataset, the date, the residuals and every estimated parameter with its standard
// deviation. `reconstruct --calibration` and every scanner loader read it as a scanner file.

struct ParameterEstimate {
  std::string name;  // e.g. "fx_px", "camera_viewport.distance_m"
  double value = 0.0;
  double std = 0.0;  // standard deviation from the solver's covariance; 0 when not estimated
};

struct StepRecord {
  std::string step;         // intrinsics | viewport | laser | laser_viewport | mems
  std::string dataset;      // the dataset folder it was computed from
  std::string date_utc;     // ISO 8601; filled by UpdateCalibration when empty
  std::string residual_unit;  // "px" or "m" or "%"
  double residual_rms = 0.0;
  double residual_max = 0.0;
  int observations = 0;     // corners, points or dots used
  double seconds = 0.0;
  std::vector<ParameterEstimate> params;
};

// Edits of a scanner file's text, each replacing one part and keeping everything else.
std::string WithCamera(const std::string& scanner_yaml, const PinholeCamera& camera);
std::string WithViewport(const std::string& scanner_yaml, const std::string& key /* camera_viewport | laser_viewport */,
                         const FlatViewport& viewport);
std::string WithGalvoLaser(const std::string& scanner_yaml, const GalvoLaser& laser);
std::string WithProjectionFunctions(const std::string& scanner_yaml, const ProjectionFunctions& functions);
// The scanner as it was when a dataset was taken: every viewport's water side in that medium
// (1.0: in air). Calibration computes with it and writes its results into the file as given,
// which keeps the medium the file is meant for. std::nullopt: the text unchanged.
std::string ScannerInMedium(const std::string& scanner_yaml, const std::optional<double>& water_index);

// Adds (or replaces) the record of record.step in the `calibration:` section.
std::string WithStepRecord(const std::string& scanner_yaml, StepRecord record);

// The records of a calibration file, in file order (empty for a plain scanner file).
std::vector<StepRecord> ReadStepRecords(const std::string& scanner_yaml, const std::string& source_name);

// Writes text to path through a temporary file and a rename: a failure leaves any earlier
// file untouched. Throws uwscan::Error naming the path.
void WriteTextAtomically(const std::filesystem::path& path, const std::string& text);

}  // namespace uwscan::scanner::calibration
