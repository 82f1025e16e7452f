#include "scanner/triangulation/triangulator_factory.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::scanner {
namespace {

ScanPattern MemsPattern() {
  ScanPattern pattern;
  pattern.kind = ScannerKind::kMems;
  pattern.mems.lines = 40;
  pattern.mems.waypoints_per_line = 30;
  return pattern;
}

// The points of one frame of `line`: a grid of stripe pixels down the middle of the image.
std::vector<TriangulatedPoint> Triangulate(const Triangulator& t, int line) {
  std::vector<Eigen::Vector2d> peaks;
  for (double v = 200.0; v < 900.0; v += 50.0) peaks.emplace_back(900.0 + 0.1 * v, v);
  std::vector<TriangulatedPoint> out(peaks.size());
  t.TriangulateFrame(line, peaks, out);
  return out;
}

// A later calibration of a MEMS scanner changes where the voltages send the beam, not which
// voltages the mirror was driven at: the lines of a log are those its own scanner designed. Here
// the calibration's polynomials are the scanner's own, but fitted over a wider drive range
// (which moves every line the pattern would design from it): on the lines the scanner drove,
// it triangulates as the scanner does, to the fit error of f5, f6 against f1, f2 (the scanner's
// own planes pass through the waypoints it aimed at, the calibration's through where f1, f2 put
// the beam at those voltages: 0.19 mm apart here); lines designed anew from it land elsewhere.
TEST(MemsCalibratedLines, ACalibrationTriangulatesTheLinesTheScannerDrove) {
  const Scanner scanner = DefaultScanner(ScannerKind::kMems);
  Scanner calibration = scanner;
  calibration.mems().functions.volts_min *= 1.2;
  calibration.mems().functions.volts_max *= 1.2;
  const ScanPattern pattern = MemsPattern();
  const auto own = MakeTriangulator(scanner, pattern, TriangulationMethod::kRayPlane);
  TriangulatorBuildOptions driven;
  driven.driven_with = scanner.mems().functions;
  const auto on_driven_lines =
      MakeTriangulator(calibration, pattern, TriangulationMethod::kRayPlane, driven);
  const auto redesigned = MakeTriangulator(calibration, pattern, TriangulationMethod::kRayPlane);
  double worst_driven_m = 0.0, worst_redesigned_m = 0.0;
  int compared = 0;
  for (int line : {0, 7, 20, 39}) {
    const std::vector<TriangulatedPoint> a = Triangulate(*own, line),
                                         b = Triangulate(*on_driven_lines, line),
                                         c = Triangulate(*redesigned, line);
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (!a[i].ok()) continue;
      ASSERT_TRUE(b[i].ok() && c[i].ok());
      worst_driven_m = std::max(worst_driven_m, (a[i].p_C - b[i].p_C).norm());
      worst_redesigned_m = std::max(worst_redesigned_m, (a[i].p_C - c[i].p_C).norm());
      ++compared;
    }
  }
  ASSERT_GT(compared, 20);
  EXPECT_LT(worst_driven_m, 0.0005);
  EXPECT_GT(worst_redesigned_m, 0.005);
  std::printf("[mems lines] driven: %.4f mm, redesigned: %.1f mm\n", worst_driven_m * 1e3,
              worst_redesigned_m * 1e3);
}

// Voltages outside the range a calibration was fitted on would extrapolate its polynomials:
// refused.
TEST(MemsCalibratedLines, LinesDrivenBeyondTheCalibratedRangeAreRefused) {
  const Scanner scanner = DefaultScanner(ScannerKind::kMems);
  Scanner narrow = scanner;
  narrow.mems().functions.volts_min *= 0.6;
  narrow.mems().functions.volts_max *= 0.6;
  TriangulatorBuildOptions driven;
  driven.driven_with = scanner.mems().functions;
  try {
    MakeTriangulator(narrow, MemsPattern(), TriangulationMethod::kRayPlane, driven);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("outside the range"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("would be extrapolated"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace uwscan::scanner
