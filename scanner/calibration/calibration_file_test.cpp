#include "scanner/calibration/calibration_file.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::scanner::calibration {
namespace {

TEST(CalibrationFile, ScannerInMediumChangesOnlyTheWaterSide) {
  const Scanner galvo = DefaultScanner(ScannerKind::kGalvo);
  const Scanner in_air = ScannerInMedium(galvo, 1.0);
  EXPECT_EQ(in_air.camera().viewport.n_water, 1.0);
  EXPECT_EQ(in_air.laser_viewport().n_water, 1.0);
  EXPECT_EQ(in_air.laser_viewport().n_glass, galvo.laser_viewport().n_glass);
  EXPECT_EQ(in_air.camera().viewport.distance_m, galvo.camera().viewport.distance_m);
  EXPECT_EQ(ScannerToYaml(ScannerInMedium(galvo, std::nullopt)), ScannerToYaml(galvo));
  // A MEMS scanner's fitted projection functions follow its laser into the new medium.
  const Scanner mems = DefaultScanner(ScannerKind::kMems);
  const Scanner mems_in_air = ScannerInMedium(mems, 1.0);
  EXPECT_NE(mems_in_air.mems().functions.f1.coefficients(),
            mems.mems().functions.f1.coefficients());
}

TEST(CalibrationFile, NowUtcIsIso8601) {
  const std::string now = NowUtc();
  ASSERT_EQ(now.size(), 20u) << now;
  EXPECT_EQ(now[4], '-');
  EXPECT_EQ(now[10], 'T');
  EXPECT_EQ(now[19], 'Z');
}

TEST(CalibrationFile, AtomicWriteKeepsTheOldFileOnFailure) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / "uwscan_calib_atomic.yaml";
  WriteFileAtomically(path, "first\n");
  EXPECT_THROW(WriteFileAtomically("/nonexistent/folder/x.yaml", "second\n"), Error);
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "first");
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace uwscan::scanner::calibration
