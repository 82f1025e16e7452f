// `uwscan simulate` of a calibration scene and `uwscan calibrate` end to end, good and bad.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>

#include "tests/cli_run.hpp"

namespace {

using uwscan::test::CommandRun;
using uwscan::test::RunUwscan;

std::string Read(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// A small intrinsics dataset (a quarter-size camera, 6 views) in a fresh folder.
class CliCalibration : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("uwscan_cli_calibration_" + std::to_string(getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_ / "scenes");
    std::filesystem::create_directories(dir_ / "scanners");
    std::filesystem::copy_file(std::string(UWSCAN_SOURCE_DIR) + "/data/scanners/galvo_default.yaml",
                               dir_ / "scanners" / "galvo_default.yaml");
    std::ofstream(dir_ / "scenes" / "small.yaml")
        << "uwscan_format: 1\n"
           "seed: 5\n"
           "water: {refractive_index: 1.0}\n"
           "scanner:\n"
           "  file: ../scanners/galvo_default.yaml\n"
           "effects:\n"
           "  refraction: false\n"
           "  image: {format: mono8}\n"
           "calibration:\n"
           "  step: intrinsics\n"
           "  pattern: {type: chessboard, columns: 9, rows: 6, square_m: 0.03}\n"
           "  views: 6\n"
           "  distance_m: [0.5, 0.8]\n"
           "  max_tilt_rad: 0.5\n"
           "  image_scale: 0.5\n";
    const CommandRun sim = RunUwscan("simulate " + (dir_ / "scenes" / "small.yaml").string() +
                                     " -o " + dataset().string());
    ASSERT_EQ(sim.exit_code, 0) << sim.output;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dataset() const { return dir_ / "dataset"; }
  std::string Calibrate(const std::string& output) const {
    return "calibrate intrinsics " + dataset().string() + " -o " + (dir_ / output).string() +
           " --from " + (dir_ / "scanners" / "galvo_default.yaml").string();
  }
  std::filesystem::path dir_;
};

TEST_F(CliCalibration, IntrinsicsFromASimulatedDatasetLandNearTheTruth) {
  const CommandRun run = RunUwscan(Calibrate("calib.yaml"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("fx_px"), std::string::npos) << run.output;
  const std::string calib = Read(dir_ / "calib.yaml");
  EXPECT_NE(calib.find("calibration:"), std::string::npos);
  EXPECT_NE(calib.find("intrinsics:"), std::string::npos);
  EXPECT_NE(calib.find("date_utc"), std::string::npos);
  // The file is a scanner file every command reads: reconstruct's parser accepts it.
  const CommandRun bench =
      RunUwscan("bench triangulation --points 1000 --scanner " + (dir_ / "calib.yaml").string());
  EXPECT_EQ(bench.exit_code, 0) << bench.output;
}

TEST_F(CliCalibration, MissingImageIsNamedAndNothingIsWritten) {
  std::filesystem::remove(dataset() / "view_002.png");
  const CommandRun run = RunUwscan(Calibrate("calib.yaml"));
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("view_002.png"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "calib.yaml"));
}

TEST_F(CliCalibration, NoPatternAnywhereIsAClearErrorAndTheOldFileStays) {
  // Every view blanked (same size, grey): no chessboard to find.
  for (const auto& entry : std::filesystem::directory_iterator(dataset())) {
    if (entry.path().extension() != ".png") continue;
    const cv::Mat image = cv::imread(entry.path().string(), cv::IMREAD_UNCHANGED);
    cv::imwrite(entry.path().string(), cv::Mat(image.size(), image.type(), cv::Scalar(90)));
  }
  std::ofstream(dir_ / "calib.yaml") << "an earlier calibration\n";
  const CommandRun run = RunUwscan(Calibrate("calib.yaml"));
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("no calibration pattern found"), std::string::npos) << run.output;
  EXPECT_EQ(Read(dir_ / "calib.yaml"), "an earlier calibration\n");  // untouched
  // A dataset of another step is refused before any work.
  const CommandRun wrong = RunUwscan("calibrate viewport " + dataset().string() + " -o " +
                                     (dir_ / "calib.yaml").string() + " --from " +
                                     (dir_ / "scanners" / "galvo_default.yaml").string());
  EXPECT_EQ(wrong.exit_code, 1) << wrong.output;
  EXPECT_NE(wrong.output.find("intrinsics"), std::string::npos) << wrong.output;
}

TEST_F(CliCalibration, InconsistentManifestNamesTheField) {
  std::string manifest = Read(dataset() / "manifest.yaml");
  const size_t at = manifest.find("step: intrinsics");
  ASSERT_NE(at, std::string::npos);
  manifest.replace(at, 16, "step: lasers");
  std::ofstream(dataset() / "manifest.yaml") << manifest;
  const CommandRun run = RunUwscan(Calibrate("calib.yaml"));
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("manifest.yaml"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("step"), std::string::npos) << run.output;
}

TEST(CliCalibrationBench, EveryStepRecoversItsTruthAndTheGaugesHoldUp) {
  const std::filesystem::path json =
      std::filesystem::temp_directory_path() /
      ("uwscan_cli_calibration_bench_" + std::to_string(getpid()) + ".json");
  const CommandRun run =
      RunUwscan("bench calibration --quick --data " + std::string(UWSCAN_SOURCE_DIR) +
                "/data --json " + json.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  const nlohmann::json& steps = j["steps"];
  for (const char* step : {"intrinsics", "viewport", "laser", "laser_viewport", "mems"}) {
    ASSERT_TRUE(steps.contains(step)) << step;
    EXPECT_GT(steps[step]["seconds"].get<double>(), 0.0) << step;
  }
  // Intrinsics within 4 standard deviations of the truth.
  for (const char* name : {"fx_px", "fy_px", "cx_px", "cy_px"}) {
    const nlohmann::json& p = steps["intrinsics"]["params"][name];
    EXPECT_LT(std::abs(p["estimated"].get<double>() - p["true"].get<double>()),
              4.0 * p["std"].get<double>())
        << name;
  }
  const nlohmann::json& distance = steps["viewport"]["params"]["camera_viewport.distance_m"];
  EXPECT_LT(std::abs(distance["estimated"].get<double>() - distance["true"].get<double>()), 1e-3);
  // The laser fans in water within a millimetre of the true ones; the MEMS beams within 2 mm.
  EXPECT_LT(steps["laser_viewport"]["params"]["fan_error_max_m"]["estimated"].get<double>(), 1e-3);
  EXPECT_LT(steps["mems"]["params"]["beam_error_max_m"]["estimated"].get<double>(), 2e-3);
  // The target: gauges with the estimated calibration within 1.5x of the true one's.
  EXPECT_LE(j["gauges"]["estimated_calibration_mean_err_m"].get<double>(),
            1.5 * j["gauges"]["true_calibration_mean_err_m"].get<double>());
  std::filesystem::remove(json);
}

}  // namespace
