// Each bench's JSON becomes the panels of its trade-off picture: which bench it is, how many
// panels, and the plotted values taken from the right fields.
#include "viewer/plots/bench_plots.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::viewer {
namespace {

namespace fs = std::filesystem;

// The JSON through a file of this process's own, removed also when reading it throws.
BenchPlots PlotsOf(const std::string& json) {
  const struct File {
    fs::path path = fs::temp_directory_path() /
                    ("uwscan_bench_plots_test_" + std::to_string(::getpid()) + ".json");
    ~File() {
      std::error_code ignored;
      fs::remove(path, ignored);
    }
  } file;
  std::ofstream(file.path) << json;
  return ReadBenchPlots(file.path);
}

const PlotSeries& SeriesNamed(const PlotSpec& plot, const std::string& prefix) {
  for (const PlotSeries& s : plot.series) {
    if (s.label.rfind(prefix, 0) == 0) return s;
  }
  throw std::runtime_error("no series '" + prefix + "' in '" + plot.title + "'");
}

TEST(BenchPlots, TriangulationTableResolutionSweepGetsItsOwnPanel) {
  const BenchPlots plots = PlotsOf(R"({"exact_vs_truth_max_m": 1e-14,
    "methods": {"ray_plane": {"mean_err_m": 8e-3, "points_per_s": 7e7}, "ray_cone": {"mean_err_m": 8e-6, "points_per_s": 4e7},
                "ray_ray": {"mean_err_m": 0, "points_per_s": 2e6}},
    "resolution": [
      {"table": "camera_rays", "value": 2, "setup_s": 0.08, "ray_cone": {"mean_err_m": 8.0e-6}},
      {"table": "camera_rays", "value": 16, "setup_s": 0.001, "ray_cone": {"mean_err_m": 1.5e-5}},
      {"table": "light_surfaces", "value": 9, "setup_s": 0.6, "ray_cone": {"mean_err_m": 8.6e-6}}]})");
  EXPECT_EQ(plots.bench, "triangulation");
  ASSERT_EQ(plots.plots.size(), 2u);
  const PlotSeries& camera = SeriesNamed(plots.plots[1], "camera-ray table");
  EXPECT_EQ(camera.label, "camera-ray table, grid px 2 16");
  EXPECT_EQ(camera.x, (std::vector<double>{0.08, 0.001}));
  EXPECT_DOUBLE_EQ(camera.y[1], 1.5e-2);  // millimetres
  EXPECT_EQ(SeriesNamed(plots.plots[1], "light-surface").x.size(), 1u);
}

TEST(BenchPlots, RegistrationShowsAddsSuccessAndTheVoxelSweep) {
  const BenchPlots plots = PlotsOf(R"({"bench": "registration",
    "pipelines": {"uwscan": {"success_rate": 0.6, "symmetric_success_rate": 0.9, "seconds_per_pair": 0.1},
                  "pcl": {"success_rate": 0.5, "symmetric_success_rate": 0.9, "seconds_per_pair": 11}},
    "voxel_sweep": [{"voxel_fraction": 0.01, "success_rate": 0.6, "symmetric_success_rate": 0.9, "seconds_per_pair": 0.4},
                    {"voxel_fraction": 0.04, "success_rate": 0.5, "symmetric_success_rate": 0.9, "seconds_per_pair": 0.05}]})");
  EXPECT_EQ(plots.bench, "registration");
  ASSERT_EQ(plots.plots.size(), 3u);
  EXPECT_EQ(SeriesNamed(plots.plots[0], "uwscan (ADD-S)").y, std::vector<double>{0.9});
  EXPECT_EQ(SeriesNamed(plots.plots[1], "ADD-S").x, (std::vector<double>{0.01, 0.04}));
  EXPECT_EQ(SeriesNamed(plots.plots[2], "seconds").y, (std::vector<double>{0.4, 0.05}));
}

TEST(BenchPlots, RecognitionAndSlamAreTellApartFromRegistration) {
  const BenchPlots recognition = PlotsOf(R"({"confusion": {},
    "pipelines": {"uwscan": {"recognition_rate": 0.25, "pose_success_rate": 0.5, "seconds_per_scan": 0.55}}})");
  EXPECT_EQ(recognition.bench, "recognition");
  EXPECT_EQ(SeriesNamed(recognition.plots[0], "uwscan: recognised").y, std::vector<double>{0.25});
  EXPECT_EQ(SeriesNamed(recognition.plots[0], "uwscan: pose").y, std::vector<double>{0.5});

  const BenchPlots slam =
      PlotsOf(R"({"dives": [{"name": "loop", "dr": {"ate_m": 0.07, "seconds": 0},
    "slam": {"ate_m": 0.06, "seconds": 8}, "open3d": {"ate_m": 0.2, "seconds": 30}},
    {"name": "pipe", "dr": {"ate_m": 0.05}, "slam": {"ate_m": 0.04, "seconds": 5}, "open3d": null}]})");
  EXPECT_EQ(slam.bench, "slam");
  const PlotSeries& loop = SeriesNamed(slam.plots[0], "loop: dead reckoning");
  EXPECT_EQ(loop.y, (std::vector<double>{0.07, 0.06}));
  EXPECT_EQ(SeriesNamed(slam.plots[0], "loop: Open3D").x, std::vector<double>{30});
  EXPECT_THROW(SeriesNamed(slam.plots[0], "pipe: Open3D"), std::runtime_error);

  EXPECT_THROW(
      PlotsOf(R"({"dives": [{"name": "loop", "dr": {}, "slam": {"ate_m": 1, "seconds": 1}}]})"),
      Error);
}

TEST(BenchPlots, LongDivesDrawTimePerSubmapAndMemoryAgainstDiveTime) {
  const BenchPlots plots = PlotsOf(R"({"bench": "slam_long", "dives": [{"name": "m4",
    "series": {"submap_time_s": [60, 120], "submap_seconds": [0.02, 0.03],
               "rss_time_s": [0, 120], "rss_bytes": [1e8, 2e8]},
    "full_solve": {"series": {"submap_time_s": [60, 120], "submap_seconds": [0.02, 0.05],
                              "rss_time_s": [0, 120], "rss_bytes": [1e8, 3e8]}}}]})");
  EXPECT_EQ(plots.bench, "slam_long");
  ASSERT_EQ(plots.plots.size(), 2u);
  const PlotSeries& windowed = SeriesNamed(plots.plots[0], "m4, windowed");
  EXPECT_EQ(windowed.x, (std::vector<double>{1.0, 2.0}));    // minutes
  EXPECT_EQ(windowed.y, (std::vector<double>{20.0, 30.0}));  // milliseconds
  EXPECT_EQ(SeriesNamed(plots.plots[1], "m4, whole graph").y, (std::vector<double>{100.0, 300.0}));
  EXPECT_THROW(PlotsOf(R"({"bench": "slam_long", "dives": [{"name": "m4",
    "series": {"submap_time_s": [60], "submap_seconds": [],
               "rss_time_s": [0], "rss_bytes": [1]}}]})"),
               Error);
}

TEST(BenchPlots, CalibrationWithGaugesIsNotTakenForTheAccuracyBench) {
  const BenchPlots plots = PlotsOf(R"({"gauges": [], "seconds": 50,
    "steps": {"intrinsics": {"seconds": 3.5}, "laser": {"seconds": 20}}})");
  EXPECT_EQ(plots.bench, "calibration");
  ASSERT_EQ(plots.plots.size(), 1u);
  EXPECT_EQ(plots.plots[0].series[0].y, (std::vector<double>{3.5, 20}));
}

}  // namespace
}  // namespace uwscan::viewer
