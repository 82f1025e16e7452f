#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bench/progress.hpp"
#include "scanner/lasers/scanner.hpp"

namespace uwscan::bench {

// The seeds' accuracy experiments, reproduced in simulation with realistic image effects
// (beam footprint, speckle, shot and read noise, ambient light; under water also attenuation
// and backscatter): stripes are rendered, detected and triangulated with the scanner's default
// method, then measured the way the seeds measured their targets.
struct AccuracyBenchOptions {
  std::filesystem::path galvo_scanner = "data/scanners/galvo_default.yaml";
  std::filesystem::path mems_scanner = "data/scanners/mems_default.yaml";
  // Seed 000: gauge blocks of 20, 50 and 100 mm at 29 positions from 0.5 to 1.2 m.
  int gauge_positions = 29;
  double gauge_near_m = 0.5;
  double gauge_far_m = 1.2;
  std::vector<double> gauge_lengths_m = {0.02, 0.05, 0.1};
  // Seed 001: a plane and a sphere of radius 100 mm at five distances (MEMS scanner), and the
  // plane at 0.6 m scanned with patterns of more and more waypoints per line.
  std::vector<double> plane_distances_m = {0.75, 1.0, 1.25, 1.5, 1.75};
  std::vector<double> sphere_distances_m = {0.75, 1.0, 1.25, 1.5, 1.75};
  double sphere_radius_m = 0.1;
  std::vector<int> waypoints_per_line = {5, 10, 20, 50, 100};
  double waypoint_plane_distance_m = 0.6;
  int mems_lines = 100;  // lines of the MEMS pattern (the seed's standard pattern has 500)
  double water_attenuation_per_m = 0.25;  // clear coastal water
  std::uint64_t seed = 1;
  int threads = 0;  // 0: OpenMP's default

  void Check() const;  // throws uwscan::Error naming the field
};

struct GaugeFigures {
  double mean_err_m = 0.0;  // mean |measured - true length|
  double std_err_m = 0.0;   // standard deviation of |measured - true length|
  double bias_m = 0.0;      // mean signed error
  int n = 0;                // gauges measured (positions x lengths with enough stripe)
  int missed = 0;           // gauges the scanner did not see well enough to measure
};

struct PlaneRow {
  double distance_m = 0.0;
  double rms_m = 0.0;  // distance of the points to their least-squares plane
  std::int64_t points = 0;
};

struct SphereRow {
  double distance_m = 0.0;
  double radius_err_m = 0.0;  // fitted minus true radius
  double rms_m = 0.0;         // radial residual of the fit
  std::int64_t points = 0;
};

struct WaypointRow {
  int waypoints_per_line = 0;
  double rms_m = 0.0;             // plane residual with the realistic effects
  double rms_noise_free_m = 0.0;  // the same with exact stripe peaks: the pattern's own error
  double lines_per_s = 0.0;
  double points_per_s = 0.0;
};

// The detector's error on the rendered stripes: each detected peak minus the exact crossing
// of its image line, along the detection axis. What a dive's `peak_noise` stands for.
struct PeakErrorFigures {
  double std_px = 0.0;
  double rms_px = 0.0;
  double bias_px = 0.0;
  double p95_abs_px = 0.0;
  std::int64_t peaks = 0;  // detected peaks matched to a crossing
};

struct AccuracyBenchResult {
  GaugeFigures gauges_air;
  GaugeFigures gauges_water;
  // The same gauges from exact stripe peaks: what the length measurement itself contributes.
  GaugeFigures gauges_air_exact;
  GaugeFigures gauges_water_exact;
  std::vector<PlaneRow> plane;
  std::vector<SphereRow> sphere;
  std::vector<WaypointRow> waypoints;
  PeakErrorFigures peak_errors_gauges_water;  // galvanometer, gauges under water (all positions)
  PeakErrorFigures peak_errors_plane;         // MEMS, the plane at every distance
  double seconds = 0.0;
};

// The gauge experiment alone, with realistic effects: the galvanometer scanner is simulated as
// options.galvo_scanner says and its stripes triangulated with `calibration` (an estimated
// calibration of that scanner) or, when std::nullopt, with the true scanner.
GaugeFigures RunGaugeExperiment(const AccuracyBenchOptions& options, bool underwater,
                                const std::optional<scanner::Scanner>& calibration,
                                const Progress& progress = {});

AccuracyBenchResult RunAccuracyBenchmark(const AccuracyBenchOptions& options,
                                         const Progress& progress = {});

}  // namespace uwscan::bench
