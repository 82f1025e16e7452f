#include "scanner/lasers/scanner_file.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <regex>
#include <string>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::scanner {
namespace {

StepRecord SomeRecord(const std::string& step) {
  StepRecord r;
  r.step = step;
  r.dataset = "/data/" + step;
  r.date_utc = "2026-01-02T03:04:05Z";
  r.residual_unit = "px";
  r.residual_rms = 0.1 / 3.0;  // not short in decimal: must survive with 17 digits
  r.residual_max = 0.25;
  r.observations = 1234;
  r.seconds = 1.5;
  r.params = {{"fx_px", 1750.0 + 1.0 / 3.0, 0.56}, {"camera_viewport.distance_m", 0.03, 1e-4}};
  return r;
}

// The numbers of two scanner files, in order: equal, but for the last bit of a rotation (a pose
// is written as a quaternion, and matrix -> quaternion -> matrix need not give the same bits).
void ExpectSameNumbers(const std::string& a, const std::string& b) {
  const std::regex number(R"([-+]?[0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)");
  std::vector<double> x, y;
  for (auto it = std::sregex_iterator(a.begin(), a.end(), number); it != std::sregex_iterator();
       ++it) {
    x.push_back(std::stod(it->str()));
  }
  for (auto it = std::sregex_iterator(b.begin(), b.end(), number); it != std::sregex_iterator();
       ++it) {
    y.push_back(std::stod(it->str()));
  }
  ASSERT_EQ(x.size(), y.size());
  for (size_t i = 0; i < x.size(); ++i)
    EXPECT_NEAR(x[i], y[i], 1e-15 * std::max(1.0, std::abs(x[i]))) << i;
}

void ExpectSamePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  EXPECT_LT((a.matrix() - b.matrix()).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(ScannerFile, GalvoScannerRoundTripsThroughItsFile) {
  Scanner s = DefaultScanner(ScannerKind::kGalvo);
  s.camera().camera.fx_px = 1751.0 + 1.0 / 7.0;
  s.galvo().laser.mirror_step_rad = 0.002 + 1e-9 / 3.0;
  s.laser_viewport().n_water = 1.3391;
  s.calibration = {SomeRecord("intrinsics"), SomeRecord("laser")};
  const std::string text = ScannerToYaml(s, "written by a test\nsecond line");
  EXPECT_EQ(text.rfind("# written by a test\n# second line\n", 0), 0u) << text;
  const Scanner back = ParseScanner(text, "round trip");
  ASSERT_EQ(back.kind(), ScannerKind::kGalvo);
  EXPECT_EQ(back.camera().camera.fx_px, s.camera().camera.fx_px);
  EXPECT_EQ(back.galvo().laser.mirror_step_rad, s.galvo().laser.mirror_step_rad);
  EXPECT_EQ(back.laser_viewport().n_water, 1.3391);
  EXPECT_EQ(back.galvo().laser.step_min, s.galvo().laser.step_min);
  ExpectSamePose(back.galvo().laser.T_C_M, s.galvo().laser.T_C_M);
  ASSERT_EQ(back.calibration.size(), 2u);
  EXPECT_EQ(back.calibration[1].step, "laser");
  EXPECT_EQ(back.calibration[0].residual_rms, s.calibration[0].residual_rms);
  EXPECT_EQ(back.calibration[0].params[0].value, s.calibration[0].params[0].value);
  EXPECT_EQ(back.calibration[0].params[1].name, "camera_viewport.distance_m");
  // Writing what was read gives the same file: nothing drifts from one generation to the next.
  ExpectSameNumbers(ScannerToYaml(back), ScannerToYaml(s));
}

TEST(ScannerFile, MemsScannerWritesOnlyCalibratedFunctions) {
  Scanner s = DefaultScanner(ScannerKind::kMems);
  ASSERT_FALSE(s.mems().functions_from_file);  // the default file has none: fitted to the laser
  const std::string fitted = ScannerToYaml(s);
  EXPECT_EQ(fitted.find("projection_functions"), std::string::npos);
  const Scanner refitted = ParseScanner(fitted, "fitted");
  EXPECT_FALSE(refitted.mems().functions_from_file);
  EXPECT_LT(
      (refitted.mems().functions.f2.coefficients() - s.mems().functions.f2.coefficients()).norm(),
      1e-12);

  s.mems().functions_from_file = true;
  const Scanner calibrated = ParseScanner(ScannerToYaml(s), "calibrated");
  EXPECT_TRUE(calibrated.mems().functions_from_file);
  EXPECT_EQ(calibrated.mems().functions.f5.coefficients(),
            s.mems().functions.f5.coefficients());  // scalars: exact
  EXPECT_EQ(calibrated.mems().dynamics.resonance_hz, s.mems().dynamics.resonance_hz);
  EXPECT_EQ(calibrated.mems().laser.saturation, s.mems().laser.saturation);
  ExpectSameNumbers(ScannerToYaml(calibrated), ScannerToYaml(s));
}

TEST(ScannerFile, AskingForTheOtherKindIsAnError) {
  const Scanner mems = DefaultScanner(ScannerKind::kMems);
  try {
    static_cast<void>(mems.galvo());
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("MEMS"), std::string::npos) << e.what();
  }
}

TEST(ScannerFile, CopySectionTakesOneSectionOnly) {
  Scanner to = DefaultScanner(ScannerKind::kGalvo);
  Scanner from = to;
  from.camera().camera.fx_px = 1000.0;
  from.laser_viewport().distance_m = 0.123;
  from.galvo().laser.mirror_step_rad = 0.003;
  CopySection(from, "laser", &to);
  EXPECT_EQ(to.galvo().laser.mirror_step_rad, 0.003);
  EXPECT_NE(to.laser_viewport().distance_m, 0.123);  // its own section
  EXPECT_NE(to.camera().camera.fx_px, 1000.0);
  CopySection(from, "laser_viewport", &to);
  EXPECT_EQ(to.laser_viewport().distance_m, 0.123);
  EXPECT_THROW(CopySection(from, "mems", &to), Error);
  EXPECT_THROW(CopySection(from, "uwscan_format", &to), Error);
  // A MEMS scanner whose functions are only fitted to its laser has none to give.
  Scanner mems_to = DefaultScanner(ScannerKind::kMems);
  Scanner mems_from = mems_to;
  EXPECT_THROW(CopySection(mems_from, "projection_functions", &mems_to), Error);
  mems_from.mems().functions_from_file = true;
  CopySection(mems_from, "projection_functions", &mems_to);
  EXPECT_TRUE(mems_to.mems().functions_from_file);
}

TEST(ScannerFile, ChangedMemsLaserRefitsOnlyFittedFunctions) {
  Scanner s = DefaultScanner(ScannerKind::kMems);
  const Eigen::VectorXd before = s.mems().functions.f1.coefficients();
  s.laser_viewport().n_water = 1.0;  // the scanner in air
  RefitSampledFunctions(&s);
  EXPECT_GT((s.mems().functions.f1.coefficients() - before).norm(), 1e-6);
  // Calibrated functions stay what the calibration found.
  Scanner calibrated = DefaultScanner(ScannerKind::kMems);
  calibrated.mems().functions_from_file = true;
  calibrated.laser_viewport().n_water = 1.0;
  RefitSampledFunctions(&calibrated);
  EXPECT_EQ(calibrated.mems().functions.f1.coefficients(), before);
}

TEST(ScannerFile, MalformedRecordsNameTheirField) {
  std::string text = ScannerToYaml([] {
    Scanner s = DefaultScanner(ScannerKind::kGalvo);
    s.calibration = {SomeRecord("viewport")};
    return s;
  }());
  text.replace(text.find("observations: 1234"), 18, "observations: many");
  try {
    ParseScanner(text, "broken.yaml");
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("broken.yaml:"), std::string::npos) << message;
    EXPECT_NE(message.find("'calibration.viewport.observations'"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace uwscan::scanner
