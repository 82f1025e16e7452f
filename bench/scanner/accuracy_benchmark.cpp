#include "bench/scanner/accuracy_benchmark.hpp"

#include <omp.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <string>

#include "perception/preprocessing/sphere_fit.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/common/parallel_tasks.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/imr_objects.hpp"
#include "scanner/sim/simulator.hpp"
#include "scanner/triangulation/light_plane.hpp"
#include "scanner/triangulation/triangulator_factory.hpp"

namespace uwscan::bench {
namespace {

using scanner::sim::ObjectShape;
using scanner::sim::Scene;
using scanner::sim::SceneObject;
using scanner::sim::SimulationEffects;
using scanner::sim::Simulator;

constexpr double kAirIndex = 1.0;
constexpr double kWaterIndex = 1.33;
// Points of one stripe farther apart than this belong to different runs (an edge between them).
constexpr double kRunBreakM = 0.003;
constexpr int kMinRunPoints = 8;

Scene BaseScene(const std::filesystem::path& scanner_path, const scanner::Scanner& model,
                double water_index, double attenuation_per_m, std::uint64_t seed) {
  Scene scene;
  scene.source = "bench accuracy";
  scene.water.refractive_index = water_index;
  scene.water.attenuation_per_m = attenuation_per_m;
  scene.scanner.file = scanner_path;
  scene.scanner.model = model;
  scene.trajectory.poses.push_back({0.0, Eigen::Isometry3d::Identity()});
  scene.detector.axis = scanner::StripeAxis::kRows;
  scene.detector.threshold = 30;
  scene.seed = seed;
  return scene;
}

Eigen::Isometry3d Pose(const Eigen::Vector3d& t,
                       const Eigen::Matrix3d& r = Eigen::Matrix3d::Identity()) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = r;
  T.translation() = t;
  return T;
}

// Builds the triangulation tables once per scanner configuration and scan pattern.
class TriangulatorCache {
 public:
  // The triangulator of the simulated scanner, or of `calibration` when it is given (a
  // calibration estimated for the same scanner).
  const scanner::Triangulator& For(const Simulator& simulator,
                                   const scanner::Scanner* calibration = nullptr) {
    const scanner::ScanPattern pattern = simulator.scan_pattern();
    const scanner::Scanner& used = calibration ? *calibration : simulator.scanner();
    // Keyed by the scanner's file text: two equal scanners share one set of tables.
    const std::string key =
        scanner::ScannerToYaml(used) + "\n#pattern\n" +
        (pattern.kind == scanner::ScannerKind::kMems ? scanner::ScanPatternToYaml(pattern)
                                                     : "galvo");
    std::unique_ptr<scanner::Triangulator>& slot = cache_[key];
    if (!slot) {
      // A MEMS calibration triangulates on the lines the simulated scanner designed and drove.
      scanner::TriangulatorBuildOptions build;
      if (calibration && pattern.kind == scanner::ScannerKind::kMems) {
        build.driven_with = simulator.scanner().mems().functions;
      }
      slot = scanner::MakeTriangulator(used, pattern,
                                       scanner::DefaultTriangulationMethod(pattern.kind), build);
    }
    return *slot;
  }

 private:
  std::map<std::string, std::unique_ptr<scanner::Triangulator>> cache_;
};

// Every frame simulated (in parallel) and triangulated: points per frame, in peak order, world
// frame. The peaks' errors are appended to `peak_errors_px` in frame order when it is given.
std::vector<std::vector<Eigen::Vector3d>> SimulateAndTriangulate(
    const Simulator& simulator, const scanner::Triangulator& triangulator, int threads,
    std::vector<double>* peak_errors_px = nullptr) {
  const std::int64_t count = simulator.frame_count();
  std::vector<std::vector<Eigen::Vector3d>> points(static_cast<size_t>(count));
  std::vector<std::vector<double>> errors(static_cast<size_t>(count));
  RunParallelTasks(count, threads, [&](std::ptrdiff_t i) {
    const scanner::sim::SimulatedFrame frame = simulator.Frame(i);
    std::vector<scanner::TriangulatedPoint> out(frame.peaks_px.size());
    triangulator.TriangulateFrame(frame.command, frame.peaks_px, out);
    for (const scanner::TriangulatedPoint& p : out) {
      if (p.ok()) points[static_cast<size_t>(i)].push_back(frame.T_W_C * p.p_C);
    }
    if (peak_errors_px)
      errors[static_cast<size_t>(i)] =
          scanner::sim::PeakErrorsPx(frame, simulator.scene().detector.axis);
  });
  if (peak_errors_px) {
    for (const std::vector<double>& e : errors)
      peak_errors_px->insert(peak_errors_px->end(), e.begin(), e.end());
  }
  return points;
}

PeakErrorFigures SummarisePeakErrors(std::vector<double> errors) {
  PeakErrorFigures f;
  f.peaks = static_cast<std::int64_t>(errors.size());
  if (errors.empty()) return f;
  double sum = 0.0, sum2 = 0.0;
  for (const double e : errors) {
    sum += e;
    sum2 += e * e;
  }
  const double n = static_cast<double>(errors.size());
  f.bias_px = sum / n;
  f.rms_px = std::sqrt(sum2 / n);
  f.std_px = std::sqrt(std::max(0.0, sum2 / n - f.bias_px * f.bias_px));
  for (double& e : errors) e = std::abs(e);
  const std::size_t at = static_cast<std::size_t>(0.95 * (n - 1));
  std::nth_element(errors.begin(), errors.begin() + static_cast<std::ptrdiff_t>(at), errors.end());
  f.p95_abs_px = errors[at];
  return f;
}

std::vector<Eigen::Vector3d> Flatten(const std::vector<std::vector<Eigen::Vector3d>>& frames) {
  std::vector<Eigen::Vector3d> all;
  for (const auto& f : frames) all.insert(all.end(), f.begin(), f.end());
  return all;
}

// Length of one run of stripe points along a gauge: its extent along its own principal
// direction plus one mean point spacing, because each end of the run stops on average half a
// spacing short of the gauge's edge (the edge falls anywhere between two image rows).
double RunLength(const std::vector<Eigen::Vector3d>& run) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : run) mean += p;
  mean /= static_cast<double>(run.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : run) cov += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  const Eigen::Vector3d axis = eig.eigenvectors().col(2);
  double lo = 0.0, hi = 0.0;
  for (const Eigen::Vector3d& p : run) {
    const double s = axis.dot(p - mean);
    lo = std::min(lo, s);
    hi = std::max(hi, s);
  }
  const double spacing = (hi - lo) / static_cast<double>(run.size() - 1);
  return hi - lo + spacing;
}

// A gauge's length from its stripes: runs of consecutive stripe points (a stripe crosses the
// gauge from end to end along its length), the median of the runs that are not cut short.
std::optional<double> MeasureGaugeLength(const std::vector<std::vector<Eigen::Vector3d>>& frames) {
  std::vector<double> lengths;
  for (const std::vector<Eigen::Vector3d>& stripe : frames) {
    std::vector<Eigen::Vector3d> run;
    auto close_run = [&] {
      if (static_cast<int>(run.size()) >= kMinRunPoints) lengths.push_back(RunLength(run));
      run.clear();
    };
    for (const Eigen::Vector3d& p : stripe) {
      if (!run.empty() && (p - run.back()).norm() > kRunBreakM) close_run();
      run.push_back(p);
    }
    close_run();
  }
  if (lengths.empty()) return std::nullopt;
  const double longest = *std::max_element(lengths.begin(), lengths.end());
  std::vector<double> full;
  for (double l : lengths) {
    if (l >= 0.8 * longest) full.push_back(l);
  }
  std::nth_element(full.begin(), full.begin() + full.size() / 2, full.end());
  return full[full.size() / 2];
}

// The galvanometer steps whose light reaches the scene's objects (an exact pass), plus one
// step either side: a gauge is scanned by the steps that can see it, as an operator would aim.
std::optional<scanner::GalvoScan> StepsOnTarget(const Scene& scene) {
  Scene exact = scene;
  exact.effects = SimulationEffects{};
  const Simulator simulator(exact);
  int first = std::numeric_limits<int>::max(), last = std::numeric_limits<int>::min();
  for (std::int64_t i = 0; i < simulator.frame_count(); ++i) {
    const scanner::sim::SimulatedFrame frame = simulator.Frame(i);
    if (frame.peaks_px.empty()) continue;
    first = std::min(first, frame.command);
    last = std::max(last, frame.command);
  }
  if (first > last) return std::nullopt;
  scanner::GalvoScan scan = scene.scanner.galvo;
  scan.step_min = std::max(scan.step_min, first - 1);
  scan.step_max = std::min(scan.step_max, last + 1);
  return scan;
}

GaugeFigures Summarise(const std::vector<double>& errors, int missed) {
  GaugeFigures g;
  g.n = static_cast<int>(errors.size());
  g.missed = missed;
  if (errors.empty()) return g;
  double sum_abs = 0.0, sum_abs2 = 0.0, sum = 0.0;
  for (double e : errors) {
    sum += e;
    sum_abs += std::abs(e);
    sum_abs2 += e * e;
  }
  g.mean_err_m = sum_abs / g.n;
  g.bias_m = sum / g.n;
  g.std_err_m = std::sqrt(std::max(0.0, sum_abs2 / g.n - g.mean_err_m * g.mean_err_m));
  return g;
}

class AccuracyRun {
 public:
  AccuracyRun(const AccuracyBenchOptions& options, const Progress& progress)
      : o_(options),
        progress_(progress),
        threads_(options.threads > 0 ? options.threads : omp_get_max_threads()),
        galvo_(scanner::LoadScanner(options.galvo_scanner)),
        mems_(scanner::LoadScanner(options.mems_scanner)) {}

  GaugeFigures Gauges(bool underwater, bool realistic, const char* stage,
                      const scanner::Scanner* calibration = nullptr) {
    std::vector<double> errors;
    int missed = 0;
    const int total = o_.gauge_positions * static_cast<int>(o_.gauge_lengths_m.size());
    int done = 0;
    for (int i = 0; i < o_.gauge_positions; ++i) {
      const double t =
          o_.gauge_positions > 1 ? static_cast<double>(i) / (o_.gauge_positions - 1) : 0.0;
      const Eigen::Vector3d position(0.06 * std::sin(1.7 * i), 0.04 * std::cos(2.3 * i),
                                     o_.gauge_near_m + t * (o_.gauge_far_m - o_.gauge_near_m));
      // Turned about the gauge's own length (y): the stripe still runs along it.
      const Eigen::Matrix3d yaw =
          Eigen::AngleAxisd(0.35 * std::sin(0.9 * i + 0.3), Eigen::Vector3d::UnitY())
              .toRotationMatrix();
      for (double length : o_.gauge_lengths_m) {
        Scene scene = BaseScene(o_.galvo_scanner, galvo_, underwater ? kWaterIndex : kAirIndex,
                                underwater ? o_.water_attenuation_per_m : 0.0,
                                o_.seed + static_cast<std::uint64_t>(1000 * i) +
                                    static_cast<std::uint64_t>(length * 1e4));
        SceneObject gauge;
        gauge.name = "gauge";
        gauge.shape = ObjectShape::kGauge;
        gauge.mesh = scanner::sim::MakeGaugeBlock(length);
        gauge.gauge_length_m = length;
        gauge.reflectance = 0.8;  // ceramic
        gauge.T_W_O = Pose(position, yaw);
        scene.objects.push_back(gauge);
        const std::optional<scanner::GalvoScan> steps = StepsOnTarget(scene);
        std::optional<double> measured;
        if (steps) {
          scene.scanner.galvo = *steps;
          if (realistic) scene.effects = scanner::sim::RealisticImageEffects(underwater);
          const Simulator simulator(scene);
          measured = MeasureGaugeLength(
              SimulateAndTriangulate(simulator, cache_.For(simulator, calibration), threads_,
                                     realistic && underwater ? &gauge_peak_errors_px_ : nullptr));
        }
        if (measured) {
          errors.push_back(*measured - length);
        } else {
          ++missed;
        }
        if (progress_) progress_(stage, static_cast<double>(++done) / total);
      }
    }
    return Summarise(errors, missed);
  }

  Scene MemsScene(int waypoints, std::uint64_t seed, bool realistic) const {
    Scene scene = BaseScene(o_.mems_scanner, mems_, kWaterIndex, o_.water_attenuation_per_m, seed);
    scene.scanner.mems.lines = o_.mems_lines;
    scene.scanner.mems.waypoints_per_line = waypoints;
    if (realistic) scene.effects = scanner::sim::RealisticImageEffects(true);
    scene.effects.mirror_dynamics = true;
    return scene;
  }

  static SceneObject PlaneAt(double distance_m) {
    SceneObject plane;
    plane.name = "plane";
    plane.shape = ObjectShape::kPlane;
    plane.mesh = scanner::sim::MakeRectangle(4.0, 4.0);
    plane.reflectance = 0.6;
    plane.T_W_O = Pose(Eigen::Vector3d(0, 0, distance_m));
    return plane;
  }

  std::vector<PlaneRow> Planes() {
    std::vector<PlaneRow> rows;
    for (size_t k = 0; k < o_.plane_distances_m.size(); ++k) {
      const double d = o_.plane_distances_m[k];
      Scene scene = MemsScene(50, o_.seed + 7 * k, true);
      scene.objects.push_back(PlaneAt(d));
      const Simulator simulator(scene);
      std::vector<double> peak_errors_px;
      const std::vector<Eigen::Vector3d> points = Flatten(
          SimulateAndTriangulate(simulator, cache_.For(simulator), threads_, &peak_errors_px));
      plane_peak_errors_px_.insert(plane_peak_errors_px_.end(), peak_errors_px.begin(),
                                   peak_errors_px.end());
      PlaneRow row;
      row.distance_m = d;
      row.points = static_cast<std::int64_t>(points.size());
      if (points.size() >= 3) row.rms_m = scanner::FitPlane(points).rms_m;
      rows.push_back(row);
      if (progress_) progress_("plane", static_cast<double>(k + 1) / o_.plane_distances_m.size());
    }
    return rows;
  }

  std::vector<SphereRow> Spheres() {
    std::vector<SphereRow> rows;
    for (size_t k = 0; k < o_.sphere_distances_m.size(); ++k) {
      const double d = o_.sphere_distances_m[k];
      Scene scene = MemsScene(50, o_.seed + 11 * k, true);
      SceneObject sphere;
      sphere.name = "sphere";
      sphere.shape = ObjectShape::kSphere;
      sphere.sphere_radius_m = o_.sphere_radius_m;
      sphere.reflectance = 0.6;
      sphere.T_W_O = Pose(Eigen::Vector3d(0, 0, d));
      scene.objects.push_back(sphere);
      const Simulator simulator(scene);
      const std::vector<Eigen::Vector3d> points =
          Flatten(SimulateAndTriangulate(simulator, cache_.For(simulator), threads_));
      SphereRow row;
      row.distance_m = d;
      row.points = static_cast<std::int64_t>(points.size());
      if (points.size() >= 4) {
        const perception::SphereFit fit = perception::FitSphere(points);
        row.radius_err_m = fit.radius_m - o_.sphere_radius_m;
        row.rms_m = fit.rms_m;
      }
      rows.push_back(row);
      if (progress_) progress_("sphere", static_cast<double>(k + 1) / o_.sphere_distances_m.size());
    }
    return rows;
  }

  std::vector<WaypointRow> Waypoints() {
    std::vector<WaypointRow> rows;
    for (size_t k = 0; k < o_.waypoints_per_line.size(); ++k) {
      const int m = o_.waypoints_per_line[k];
      WaypointRow row;
      row.waypoints_per_line = m;
      for (const bool realistic : {true, false}) {
        Scene scene = MemsScene(m, o_.seed + 13 * k, realistic);
        scene.objects.push_back(PlaneAt(o_.waypoint_plane_distance_m));
        const Simulator simulator(scene);
        const std::vector<Eigen::Vector3d> points =
            Flatten(SimulateAndTriangulate(simulator, cache_.For(simulator), threads_));
        const double rms = points.size() >= 3 ? scanner::FitPlane(points).rms_m : 0.0;
        (realistic ? row.rms_m : row.rms_noise_free_m) = rms;
        if (realistic) {
          row.lines_per_s = 1.0 / simulator.frame_period_s();
          row.points_per_s = row.lines_per_s * static_cast<double>(points.size()) /
                             static_cast<double>(simulator.frame_count());
        }
      }
      rows.push_back(row);
      if (progress_)
        progress_("waypoints", static_cast<double>(k + 1) / o_.waypoints_per_line.size());
    }
    return rows;
  }

  // The realistic runs' peak errors so far (Gauges under water, Planes).
  PeakErrorFigures GaugePeakErrors() const { return SummarisePeakErrors(gauge_peak_errors_px_); }
  PeakErrorFigures PlanePeakErrors() const { return SummarisePeakErrors(plane_peak_errors_px_); }

 private:
  const AccuracyBenchOptions& o_;
  const Progress& progress_;
  int threads_;
  scanner::Scanner galvo_;
  scanner::Scanner mems_;
  TriangulatorCache cache_;
  std::vector<double> gauge_peak_errors_px_;
  std::vector<double> plane_peak_errors_px_;
};

}  // namespace

void AccuracyBenchOptions::Check() const {
  const OptionChecks check("AccuracyBenchOptions");
  const auto index = [](const char* field, std::size_t i) {
    return std::string(field) + "[" + std::to_string(i) + "]";
  };
  check.AtLeast("gauge_positions", gauge_positions, 1);
  check.GreaterThan("gauge_near_m", gauge_near_m, 0.0, "m");
  check.Require(gauge_far_m >= gauge_near_m, "gauge_far_m",
                ">= gauge_near_m (" + OptionValueText(gauge_near_m) + " m)", gauge_far_m);
  for (std::size_t i = 0; i < gauge_lengths_m.size(); ++i) {
    if (!(gauge_lengths_m[i] > 0.0)) {
      check.Fail(index("gauge_lengths_m", i), "> 0 m", OptionValueText(gauge_lengths_m[i]));
    }
  }
  for (std::size_t i = 0; i < plane_distances_m.size(); ++i) {
    if (!(plane_distances_m[i] > 0.0)) {
      check.Fail(index("plane_distances_m", i), "> 0 m", OptionValueText(plane_distances_m[i]));
    }
  }
  for (std::size_t i = 0; i < sphere_distances_m.size(); ++i) {
    if (!(sphere_distances_m[i] > sphere_radius_m)) {
      check.Fail(index("sphere_distances_m", i),
                 "> sphere_radius_m (" + OptionValueText(sphere_radius_m) + " m)",
                 OptionValueText(sphere_distances_m[i]));
    }
  }
  for (std::size_t i = 0; i < waypoints_per_line.size(); ++i) {
    if (waypoints_per_line[i] < 2) {
      check.Fail(index("waypoints_per_line", i), ">= 2", std::to_string(waypoints_per_line[i]));
    }
  }
  check.AtLeast("mems_lines", mems_lines, 1);
  check.AtLeast("threads", threads, 0);
}

GaugeFigures RunGaugeExperiment(const AccuracyBenchOptions& options, bool underwater,
                                const std::optional<scanner::Scanner>& calibration,
                                const Progress& progress) {
  options.Check();
  AccuracyRun run(options, progress);
  return run.Gauges(underwater, true, underwater ? "gauges in water" : "gauges in air",
                    calibration ? &*calibration : nullptr);
}

AccuracyBenchResult RunAccuracyBenchmark(const AccuracyBenchOptions& options,
                                         const Progress& progress) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  AccuracyRun run(options, progress);
  AccuracyBenchResult result;
  result.gauges_air = run.Gauges(false, true, "gauges in air");
  result.gauges_water = run.Gauges(true, true, "gauges in water");
  result.peak_errors_gauges_water = run.GaugePeakErrors();
  result.gauges_air_exact = run.Gauges(false, false, "gauges in air, exact peaks");
  result.gauges_water_exact = run.Gauges(true, false, "gauges in water, exact peaks");
  result.plane = run.Planes();
  result.peak_errors_plane = run.PlanePeakErrors();
  result.sphere = run.Spheres();
  result.waypoints = run.Waypoints();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace uwscan::bench
