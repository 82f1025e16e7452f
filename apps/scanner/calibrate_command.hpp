#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `calibrate STEP DATASET -o CALIB.yaml [--from SCANNER.yaml]`: one calibration step.
void AddCalibrateCommand(CLI::App& app);
// `import-intrinsics OPENCV.yaml --into SCANNER.yaml -o CALIB.yaml`.
void AddImportIntrinsicsCommand(CLI::App& app);

}  // namespace uwscan::app
