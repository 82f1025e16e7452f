#include "scanner/calibration/calibration_file.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "scanner/common/error.hpp"
#include "scanner/lasers/mems_scanner_model.hpp"
#include "scanner/lasers/scanner_model.hpp"

namespace uwscan::scanner::calibration {
namespace {

std::string ReadSource(const std::string& relative) {
  std::ifstream in(std::string(UWSCAN_SOURCE_DIR_FOR_TESTS) + "/" + relative);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(CalibrationFile, EditsRoundTripThroughTheScannerParser) {
  std::string yaml = ReadSource("data/scanners/galvo_default.yaml");
  ScannerModel model = ParseScannerModel(yaml, "galvo");
  model.camera.camera.fx_px = 1751.25;
  model.camera.camera.k1 = -0.125;
  model.camera.viewport.distance_m = 0.0312;
  model.laser.mirror_step_rad = 0.00201;
  model.laser.T_C_L.translation().x() += 0.001;
  model.laser.viewport.thickness_m = 0.0151;
  yaml = WithCamera(yaml, model.camera.camera);
  yaml = WithViewport(yaml, "camera_viewport", model.camera.viewport);
  yaml = WithViewport(yaml, "laser_viewport", model.laser.viewport);
  yaml = WithGalvoLaser(yaml, model.laser);
  StepRecord record;
  record.step = "intrinsics";
  record.dataset = "/data/calib/intrinsics";
  record.residual_unit = "px";
  record.residual_rms = 0.21;
  record.residual_max = 0.9;
  record.observations = 540;
  record.params = {{"fx_px", 1751.25, 0.4}, {"fy_px", 1750.5, 0.41}};
  yaml = WithStepRecord(yaml, record);
  const ScannerModel back = ParseScannerModel(yaml, "calibrated");
  EXPECT_EQ(back.camera.camera.fx_px, 1751.25);
  EXPECT_EQ(back.camera.camera.k1, -0.125);
  EXPECT_EQ(back.camera.viewport.distance_m, 0.0312);
  EXPECT_EQ(back.laser.viewport.thickness_m, 0.0151);
  EXPECT_EQ(back.laser.mirror_step_rad, 0.00201);
  EXPECT_TRUE(back.laser.T_C_L.isApprox(model.laser.T_C_L, 1e-15));
  const std::vector<StepRecord> records = ReadStepRecords(yaml, "calibrated");
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0].dataset, "/data/calib/intrinsics");
  EXPECT_EQ(records[0].date_utc.size(), 20u);
  ASSERT_EQ(records[0].params.size(), 2u);
  EXPECT_EQ(records[0].params[1].std, 0.41);
  // A second record of the same step replaces the first; another step is added.
  record.residual_rms = 0.19;
  yaml = WithStepRecord(yaml, record);
  record.step = "viewport";
  yaml = WithStepRecord(yaml, record);
  const std::vector<StepRecord> two = ReadStepRecords(yaml, "calibrated");
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[0].residual_rms, 0.19);
}

TEST(CalibrationFile, ProjectionFunctionsRoundTrip) {
  std::string yaml = ReadSource("data/scanners/mems_default.yaml");
  const MemsScannerModel model = ParseMemsScannerModel(yaml, "mems");
  yaml = WithProjectionFunctions(yaml, model.functions);
  const MemsScannerModel back = ParseMemsScannerModel(yaml, "calibrated");
  const Eigen::Vector2d volts(1.5, -3.25);
  EXPECT_EQ(back.functions.PointAt(volts), model.functions.PointAt(volts));
  EXPECT_EQ(back.functions.VoltsAt(Eigen::Vector2d(0.01, 0.02)),
            model.functions.VoltsAt(Eigen::Vector2d(0.01, 0.02)));
}

TEST(CalibrationFile, AtomicWriteKeepsTheOldFileOnFailure) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "uwscan_calib_atomic.yaml";
  WriteTextAtomically(path, "first\n");
  EXPECT_THROW(WriteTextAtomically("/nonexistent/folder/x.yaml", "second\n"), Error);
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "first");
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace uwscan::scanner::calibration
