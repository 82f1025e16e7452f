#include "bench/scanner/calibration_benchmark.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <map>

#include "bench/scanner/accuracy_benchmark.hpp"
#include "bench/scratch_folder.hpp"
#include "scanner/calibration/calibration_dataset.hpp"
#include "scanner/calibration/calibration_steps.hpp"
#include "scanner/calibration/dataset_simulation.hpp"
#include "scanner/calibration/galvo_laser_calibration.hpp"
#include "scanner/calibration/parameter_lists.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::bench {
namespace {

namespace cal = scanner::calibration;
using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// The true values of the parameters a step records, by name.
std::map<std::string, double> TrueValues(const std::string& step,
                                         const scanner::Scanner& true_scanner) {
  std::vector<scanner::ParameterEstimate> list;
  if (step == "mems") return {};
  const scanner::GalvoScannerModel& truth = true_scanner.galvo();
  if (step == "intrinsics") list = cal::CameraParameters(truth.camera.camera);
  if (step == "viewport") list = cal::ViewportParameters("camera_viewport", truth.camera.viewport);
  if (step == "laser") list = cal::GalvoLaserParameters(truth.laser);
  if (step == "laser_viewport")
    list = cal::ViewportParameters("laser_viewport", truth.laser.viewport);
  std::map<std::string, double> values;
  for (const scanner::ParameterEstimate& p : list) values[p.name] = p.value;
  return values;
}

// Largest distance, at 0.8 and 1.5 m deep, between the estimated MEMS beams and the true ones,
// at the voltage pairs the dataset saw on two planes or more (where the functions were fitted;
// beyond them a polynomial extrapolates).
double MemsBeamError(const scanner::Scanner& estimated_scanner,
                     const scanner::Scanner& true_scanner, const cal::CalibrationDataset& dataset) {
  const scanner::MemsScannerModel& estimated = estimated_scanner.mems();
  const scanner::MemsScannerModel& truth = true_scanner.mems();
  std::map<std::pair<double, double>, int> planes_of;
  for (const cal::CalibrationDataset::Plane& plane : dataset.planes) {
    for (const auto& dot : plane.dots) ++planes_of[{dot.second.x(), dot.second.y()}];
  }
  double worst = 0.0;
  for (const auto& [key, planes] : planes_of) {
    if (planes < 2) continue;
    const Eigen::Vector2d volts(key.first, key.second);
    const scanner::RayTrace e = estimated.functions.RayInWater_C(volts);
    const scanner::RayTrace t = truth.laser.RayInWater(volts);
    if (!e.ok() || !t.ok()) continue;
    for (const double depth : {0.8, 1.5}) {
      const Eigen::Vector3d pe = e.ray.At((depth - e.ray.origin.z()) / e.ray.direction.z());
      const Eigen::Vector3d pt = t.ray.At((depth - t.ray.origin.z()) / t.ray.direction.z());
      worst = std::max(worst, (pe - pt).norm());
    }
  }
  return worst;
}

// Largest distance from points of the true laser fans (every 20th mirror step, 15 rays each,
// 0.5-1.5 m deep) to the estimated fans, both in the dataset's medium: what the laser
// calibration is for, whatever gauge its parameters are expressed in.
double FanError(const scanner::Scanner& true_scanner, const scanner::Scanner& estimated_scanner,
                const std::optional<double>& water_index) {
  const scanner::GalvoScannerModel truth = cal::ScannerInMedium(true_scanner, water_index).galvo();
  const scanner::GalvoScannerModel estimated =
      cal::ScannerInMedium(estimated_scanner, water_index).galvo();
  double worst = 0.0;
  const double max_tan = truth.laser.MaxFanTan();
  for (int step = truth.laser.step_min; step <= truth.laser.step_max; step += 20) {
    const scanner::LaserFan fan = truth.laser.FanAtStep(step);
    for (int k = 0; k < 15; ++k) {
      const scanner::RayTrace ray = fan.RayInWater(-max_tan + 2.0 * max_tan * k / 14.0);
      if (!ray.ok() || !(ray.ray.direction.z() > 1e-6)) continue;
      for (const double depth : {0.5, 1.0, 1.5}) {
        const Eigen::Vector3d p = ray.ray.At((depth - ray.ray.origin.z()) / ray.ray.direction.z());
        const std::optional<double> d = cal::DistanceToFan(estimated.laser, step, p);
        // A true point the estimated fan cannot reach at all is as wrong as can be.
        worst = d ? std::max(worst, *d) : std::numeric_limits<double>::infinity();
      }
    }
  }
  return worst;
}

}  // namespace

void CalibrationBenchOptions::Check() const {
  const OptionChecks check("CalibrationBenchOptions");
  check.AtLeast("gauge_positions", gauge_positions, 1);
  check.AtLeast("threads", threads, 0);
  check.Require(std::filesystem::is_directory(data_dir / "scenes"), "data_dir",
                "a data folder with scenes/ (give --data)", OptionQuotedText(data_dir.string()));
}

CalibrationBenchResult RunCalibrationBenchmark(const CalibrationBenchOptions& options,
                                               const Progress& progress) {
  options.Check();
  const Clock::time_point start = Clock::now();
  ScratchFolder scratch("bench-calibration");
  CalibrationBenchResult result;
  std::optional<scanner::Scanner>
      galvo_chain;  // the galvanometer calibration as it grows step by step
  const std::vector<std::string>& steps = cal::CalibrationSteps();
  for (size_t k = 0; k < steps.size(); ++k) {
    const std::string& step = steps[k];
    StepFigures figures;
    figures.step = step;
    const std::filesystem::path folder = scratch.path() / step;
    const Clock::time_point simulated = Clock::now();
    cal::SimulateCalibrationDataset(options.data_dir / "scenes" / ("calib_" + step + ".yaml"),
                                    folder, [&](double f) {
                                      if (progress) progress("dataset " + step, f);
                                    });
    figures.dataset_seconds = Seconds(simulated);
    const cal::CalibrationDataset dataset = cal::LoadCalibrationDataset(folder);
    if (!dataset.truth_file)
      throw Error(folder.string() + ": a simulated dataset must name its truth");
    const scanner::Scanner truth = cal::LoadDatasetTruth(*dataset.truth_file).scanner;
    // The galvanometer steps start from the previous step's output, as a user chains them.
    const bool chained = step != "mems" && step != "intrinsics" && galvo_chain.has_value();
    // Intrinsics need no starting values: they are written into the CAD scanner file.
    const std::filesystem::path start_file = dataset.scanner_file
                                                 ? *dataset.scanner_file
                                                 : options.data_dir / "scanners" / "galvo_cad.yaml";
    const scanner::Scanner initial = chained ? *galvo_chain : scanner::LoadScanner(start_file);
    const cal::CalibrationStepOutcome outcome = cal::RunCalibrationStep(
        step, dataset, initial, chained ? "the previous step's output" : start_file.string(),
        [&](double f) {
          if (progress) progress("calibrate " + step, f);
        });
    if (step != "mems") {
      galvo_chain = outcome.scanner;
    }
    figures.seconds = outcome.record.seconds;
    figures.residual_rms = outcome.record.residual_rms;
    figures.residual_unit = outcome.record.residual_unit;
    const std::map<std::string, double> truth_values = TrueValues(step, truth);
    for (const scanner::ParameterEstimate& p : outcome.record.params) {
      const auto it = truth_values.find(p.name);
      figures.params.push_back(
          {p.name, it == truth_values.end() ? std::numeric_limits<double>::quiet_NaN() : it->second,
           p.value, p.std});
    }
    if (step == "mems") {
      figures.params.push_back(
          {"beam_error_max_m", 0.0, MemsBeamError(outcome.scanner, truth, dataset), 0.0});
    }
    if (step == "laser" || step == "laser_viewport") {
      figures.params.push_back({"fan_error_max_m", 0.0,
                                FanError(truth, outcome.scanner, dataset.water_refractive_index),
                                0.0});
    }
    result.steps.push_back(figures);
  }

  // The seed's gauges under water, triangulated with the chained estimate and with the truth.
  AccuracyBenchOptions gauges;
  gauges.galvo_scanner = options.data_dir / "scanners" / "galvo_default.yaml";
  gauges.mems_scanner = options.data_dir / "scanners" / "mems_default.yaml";
  gauges.gauge_positions = options.gauge_positions;
  gauges.seed = options.seed;
  gauges.threads = options.threads;
  const GaugeFigures with_truth = RunGaugeExperiment(gauges, true, std::nullopt, progress);
  const GaugeFigures with_estimate = RunGaugeExperiment(gauges, true, galvo_chain, progress);
  result.gauges_true_calibration_mean_err_m = with_truth.mean_err_m;
  result.gauges_estimated_calibration_mean_err_m = with_estimate.mean_err_m;
  result.gauges = with_estimate.n;
  result.seconds = Seconds(start);
  return result;
}

}  // namespace uwscan::bench
