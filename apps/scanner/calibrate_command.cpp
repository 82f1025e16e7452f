#include "apps/scanner/calibrate_command.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "apps/cli/output_path.hpp"
#include "apps/cli/progress_bar.hpp"
#include "scanner/calibration/calibration_dataset.hpp"
#include "scanner/calibration/calibration_steps.hpp"
#include "scanner/calibration/opencv_camera_import.hpp"
#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/optics/pinhole_camera.hpp"

namespace uwscan::app {
namespace {

using scanner::PinholeCamera;

struct CalibrateArgs {
  std::string step;
  std::string dataset;
  std::string output;
  std::string from;
  scanner::calibration::CalibrationStepOptions options;
};

void RunCalibrate(const CalibrateArgs& a) {
  CheckOutputPath(a.output, "-o",
                  {a.dataset, a.from, std::filesystem::path(a.dataset) / "manifest.yaml"});
  const scanner::calibration::CalibrationDataset dataset =
      scanner::calibration::LoadCalibrationDataset(a.dataset);
  std::filesystem::path initial;
  if (!a.from.empty()) {
    initial = a.from;
  } else if (dataset.scanner_file) {
    initial = *dataset.scanner_file;
  } else {
    throw Error(a.dataset +
                ": the manifest names no scanner file to start from; give --from SCANNER.yaml");
  }
  scanner::calibration::CalibrationStepOutcome outcome;
  {
    ProgressBar bar;
    outcome = scanner::calibration::RunCalibrationStep(
        a.step, dataset, scanner::LoadScanner(initial), initial.string(),
        [&bar, &a](double f) { bar.Update("calibrate " + a.step, f); }, a.options);
  }
  WriteFileAtomically(a.output, scanner::ScannerToYaml(outcome.scanner));
  std::printf("%s: step %s from %s, started from %s, %.2f s\n", a.output.c_str(), a.step.c_str(),
              a.dataset.c_str(), initial.string().c_str(), outcome.record.seconds);
  for (const std::string& line : outcome.summary) std::printf("  %s\n", line.c_str());
  std::printf("\n| parameter | value | std |\n|---|---:|---:|\n");
  for (const scanner::ParameterEstimate& p : outcome.record.params) {
    std::printf("| %s | %.9g | %.3g |\n", p.name.c_str(), p.value, p.std);
  }
}

struct ImportArgs {
  std::string opencv_yaml;
  std::string into;
  std::string output;
};

void RunImportIntrinsics(const ImportArgs& a) {
  CheckOutputPath(a.output, "-o", {a.opencv_yaml, a.into});
  const PinholeCamera camera = scanner::calibration::ImportOpenCvCalibration(a.opencv_yaml);
  scanner::Scanner calibrated = scanner::LoadScanner(a.into);
  const PinholeCamera& current = calibrated.camera().camera;
  if (camera.width_px != current.width_px || camera.height_px != current.height_px) {
    // Intrinsics belong to one image size: those of a binned or cropped image would place every
    // stripe peak of the scanner's full frames wrongly.
    throw Error(a.opencv_yaml + ": calibrated on " + std::to_string(camera.width_px) + "x" +
                std::to_string(camera.height_px) + " images, the camera of " + a.into + " gives " +
                std::to_string(current.width_px) + "x" + std::to_string(current.height_px) +
                " (calibrate at the camera's own resolution)");
  }
  calibrated.camera().camera = camera;
  scanner::StepRecord record;
  record.step = "intrinsics";
  record.dataset =
      "imported from " + std::filesystem::absolute(a.opencv_yaml).lexically_normal().string();
  record.residual_unit = "px";
  record.params = {{"fx_px", camera.fx_px, 0.0},
                   {"fy_px", camera.fy_px, 0.0},
                   {"cx_px", camera.cx_px, 0.0},
                   {"cy_px", camera.cy_px, 0.0}};
  record.date_utc = scanner::calibration::NowUtc();
  scanner::SetStepRecord(&calibrated, record);
  WriteFileAtomically(a.output, scanner::ScannerToYaml(calibrated));
  std::printf("%s: intrinsics from %s (fx %.3f, fy %.3f, cx %.3f, cy %.3f px; k1 %.6g) into %s\n",
              a.output.c_str(), a.opencv_yaml.c_str(), camera.fx_px, camera.fy_px, camera.cx_px,
              camera.cy_px, camera.k1, a.into.c_str());
}

}  // namespace

void AddImportIntrinsicsCommand(CLI::App& app) {
  auto args = std::make_shared<ImportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "import-intrinsics",
      "put intrinsics from OpenCV's calibration YAML or XML into a scanner file");
  cmd->add_option("opencv_yaml", args->opencv_yaml,
                  "camera_matrix + distortion_coefficients (OpenCV)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--into", args->into, "scanner file to take everything else from")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", args->output, "calibration file to write")->required();
  cmd->callback([args] { RunImportIntrinsics(*args); });
}

void AddCalibrateCommand(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand("calibrate", "run one calibration step on a dataset folder");
  cmd->add_option("step", args->step, "intrinsics, viewport, laser, laser_viewport or mems")
      ->required();
  cmd->add_option("dataset", args->dataset, "dataset folder (manifest.yaml + images)")->required();
  cmd->add_option("-o,--output", args->output,
                  "calibration file to write (a scanner YAML with a calibration record)")
      ->required();
  cmd->add_option("--from", args->from,
                  "scanner file to start from (CAD values or an earlier step's output; default: "
                  "the manifest's)");
  cmd->add_flag("--refine-thickness", args->options.refine_thickness,
                "viewport steps: also estimate the viewport thickness (weakly observable)");
  cmd->add_flag("--refine-water-index", args->options.refine_water_index,
                "camera viewport: also estimate the water's refractive index");
  cmd->add_flag("--refine-glass-index", args->options.refine_glass_index,
                "camera viewport: also estimate the glass's refractive index (weakly observable)");
  cmd->callback([args] { RunCalibrate(*args); });
}

}  // namespace uwscan::app
