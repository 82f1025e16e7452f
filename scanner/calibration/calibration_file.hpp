#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "scanner/common/atomic_file.hpp"  // WriteFileAtomically, used with these files
#include "scanner/lasers/scanner.hpp"

namespace uwscan::scanner::calibration {

// A calibration file is a scanner file (galvanometer or MEMS, data/README.md) whose values are
// the calibrated ones, plus a `calibration:` section recording, per step, where they came
// from (StepRecord: the dataset, the date, the residuals and every estimated parameter with
// its standard deviation). It is read and written as a Scanner (scanner/lasers/scanner_file).

// The scanner as it was when a dataset was taken: every viewport's water side in that medium
// (1.0: in air). Calibration computes with it and writes its results into the scanner as given,
// which keeps the medium the file is meant for. std::nullopt: the scanner unchanged.
Scanner ScannerInMedium(Scanner scanner, const std::optional<double>& water_index);

// The current time as ISO 8601 UTC ("2024-05-01T12:34:56Z"), for StepRecord::date_utc.
std::string NowUtc();

}  // namespace uwscan::scanner::calibration
