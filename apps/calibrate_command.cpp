#include "apps/calibrate_command.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "apps/progress_bar.hpp"
#include "scanner/calibration/calibration_dataset.hpp"
#include "scanner/calibration/calibration_steps.hpp"
#include "scanner/error.hpp"

namespace uwscan::app {
namespace {

struct CalibrateArgs {
  std::string step;
  std::string dataset;
  std::string output;
  std::string from;
};

std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot read");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void RunCalibrate(const CalibrateArgs& a) {
  const std::filesystem::path parent = std::filesystem::path(a.output).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent)) {
    throw Error("-o " + a.output + ": folder '" + parent.string() + "' does not exist");
  }
  const scanner::calibration::CalibrationDataset dataset =
      scanner::calibration::LoadCalibrationDataset(a.dataset);
  std::filesystem::path initial;
  if (!a.from.empty()) {
    initial = a.from;
  } else if (dataset.scanner_file) {
    initial = *dataset.scanner_file;
  } else {
    throw Error(a.dataset + ": the manifest names no scanner file to start from; give --from SCANNER.yaml");
  }
  scanner::calibration::CalibrationStepOutcome outcome;
  {
    ProgressBar bar;
    outcome = scanner::calibration::RunCalibrationStep(
        a.step, dataset, ReadText(initial), initial.string(),
        [&bar, &a](double f) { bar.Update("calibrate " + a.step, f); });
  }
  scanner::calibration::WriteTextAtomically(a.output, outcome.scanner_yaml);
  std::printf("%s: step %s from %s, started from %s, %.2f s\n", a.output.c_str(), a.step.c_str(),
              a.dataset.c_str(), initial.string().c_str(), outcome.record.seconds);
  for (const std::string& line : outcome.summary) std::printf("  %s\n", line.c_str());
  std::printf("\n| parameter | value | std |\n|---|---:|---:|\n");
  for (const scanner::calibration::ParameterEstimate& p : outcome.record.params) {
    std::printf("| %s | %.9g | %.3g |\n", p.name.c_str(), p.value, p.std);
  }
}

}  // namespace

void AddCalibrateCommand(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand("calibrate", "run one calibration step on a dataset folder");
  cmd->add_option("step", args->step, "intrinsics, viewport, laser, laser_viewport or mems")->required();
  cmd->add_option("dataset", args->dataset, "dataset folder (manifest.yaml + images)")->required();
  cmd->add_option("-o,--output", args->output, "calibration file to write (a scanner YAML with a calibration record)")
      ->required();
  cmd->add_option("--from", args->from,
                  "scanner file to start from (CAD values or an earlier step's output; default: the manifest's)");
  cmd->callback([args] { RunCalibrate(*args); });
}

}  // namespace uwscan::app
