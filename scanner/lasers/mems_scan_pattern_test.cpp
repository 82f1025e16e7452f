#include "scanner/lasers/mems_scan_pattern.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/lasers/mems_scanner_model.hpp"
#include "scanner/lasers/mirror_dynamics.hpp"

namespace uwscan::scanner {
namespace {

class MemsScanPatternTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    model_ = std::make_unique<MemsScannerModel>(DefaultMemsScannerModel());
  }
  static void TearDownTestSuite() { model_.reset(); }
  static std::unique_ptr<MemsScannerModel> model_;
};
std::unique_ptr<MemsScannerModel> MemsScanPatternTest::model_;

// Distances of the true beams along a line's mirror path to the line's plane, at camera
// depths 0.6, 1.25 and 1.5 m: how planar the light really is.
struct Planarity {
  double rms_m[3] = {0.0, 0.0, 0.0};
  double max_m[3] = {0.0, 0.0, 0.0};
};
constexpr double kDepths[3] = {0.6, 1.25, 1.5};

Planarity MeasurePlanarity(const MemsScannerModel& model, const std::vector<MemsLine>& lines,
                           bool dynamics) {
  Planarity result;
  int count = 0;
  for (const MemsLine& line : lines) {
    const TiltPath path = SimulateLine(model.laser, line.volts, model.dynamics, dynamics);
    for (const TiltSample& s : path.samples) {
      const RayTrace beam = model.laser.RayInWaterFromTilt(s.tilt_rad);
      EXPECT_TRUE(beam.ok());
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d p =
            beam.ray.At((kDepths[k] - beam.ray.origin.z()) / beam.ray.direction.z());
        const double d = std::abs(line.plane_C.normal.dot(p) - line.plane_C.offset_m);
        result.rms_m[k] += d * d;
        result.max_m[k] = std::max(result.max_m[k], d);
      }
      ++count;
    }
  }
  for (double& r : result.rms_m) r = std::sqrt(r / count);
  return result;
}

TEST_F(MemsScanPatternTest, LayoutFollowsTheSeed) {
  MemsScanPatternOptions options;
  options.lines = 7;
  options.waypoints_per_line = 11;
  const ProjectionFunctions& f = model_->functions;
  const std::vector<MemsLine> lines = DesignMemsScanPattern(f, options);
  ASSERT_EQ(lines.size(), 7u);
  const FovLimits fov = f.Fov();
  const Eigen::Vector2d centre = 0.5 * (fov.p_min_m + fov.p_max_m);
  const Eigen::Vector2d half(0.5 * options.fov_fraction_x * (fov.p_max_m.x() - fov.p_min_m.x()),
                             0.5 * options.fov_fraction_y * (fov.p_max_m.y() - fov.p_min_m.y()));
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const MemsLine& line = lines[i];
    ASSERT_EQ(line.p_P.size(), 11u);
    ASSERT_EQ(line.volts.size(), 11u);
    const double expected_x = centre.x() + half.x() * (2.0 * i / 6.0 - 1.0);
    for (std::size_t j = 0; j < line.p_P.size(); ++j) {
      EXPECT_EQ(line.p_P[j].x(), line.p_P[0].x());  // constant p_x: a vertical line
      EXPECT_NEAR(line.p_P[j].x(), expected_x, 1e-15);
      EXPECT_NEAR(line.p_P[j].y(), centre.y() + half.y() * (2.0 * j / 10.0 - 1.0), 1e-15);
      EXPECT_EQ(line.volts[j], f.VoltsAt(line.p_P[j]));  // eq. 11
      EXPECT_TRUE(f.InDriveRange(line.volts[j]));
    }
    // The plane holds its waypoints and their beams (eqs. 12-14).
    EXPECT_LT(line.plane_rms_m, 50e-6);
    for (std::size_t j = 0; j < line.p_P.size(); ++j) {
      const Eigen::Vector3d p_C = f.T_C_P * Eigen::Vector3d(line.p_P[j].x(), line.p_P[j].y(), 0.0);
      EXPECT_LT(std::abs(line.plane_C.normal.dot(p_C) - line.plane_C.offset_m), 100e-6);
    }
    // Lines are vertical in water: their planes contain (nearly) the camera's y axis.
    EXPECT_LT(std::abs(line.plane_C.normal.y()), 0.05);
  }
  // One line runs through the centre.
  options.lines = 1;
  const std::vector<MemsLine> one = DesignMemsScanPattern(f, options);
  EXPECT_NEAR(one[0].p_P[0].x(), centre.x(), 1e-15);
}

TEST_F(MemsScanPatternTest, LinesBecomePlanesInWater) {
  // Seed Fig. 5 and 13: more waypoints per line, flatter light, since the mirror runs straight
  // in angle space between waypoints, off the pre-curved ideal. Measured on the true laser.
  std::cout << "[ measured ] m | eq.14 rms (worst line) | true beams to plane, ideal path: rms/max"
               " at 0.6, 1.25, 1.5 m | with mirror dynamics at 1.25 m | lines/s  (um)\n";
  double rms_at_5 = 0.0, rms_at_50 = 0.0;
  for (const int m : {5, 10, 20, 50, 100}) {
    MemsScanPatternOptions options;
    options.lines = 21;
    options.waypoints_per_line = m;
    const std::vector<MemsLine> lines = DesignMemsScanPattern(model_->functions, options);
    double fit_rms = 0.0, fit_worst = 0.0;
    for (const MemsLine& line : lines) {
      fit_rms += line.plane_rms_m * line.plane_rms_m / lines.size();
      fit_worst = std::max(fit_worst, line.plane_rms_m);
    }
    const Planarity ideal = MeasurePlanarity(*model_, lines, false);
    const Planarity dynamic = MeasurePlanarity(*model_, lines, true);
    std::ostringstream row;
    row << std::fixed << std::setprecision(1) << "[ measured ] " << std::setw(3) << m << " | "
        << std::sqrt(fit_rms) * 1e6 << " (" << fit_worst * 1e6 << ") |";
    for (int k = 0; k < 3; ++k) row << " " << ideal.rms_m[k] * 1e6 << "/" << ideal.max_m[k] * 1e6;
    row << " | " << dynamic.rms_m[1] * 1e6 << "/" << dynamic.max_m[1] * 1e6 << " | "
        << LinesPerSecond(m, model_->dynamics) << "\n";
    std::cout << row.str();
    if (m == 5) rms_at_5 = ideal.rms_m[1];
    if (m == 50) {
      rms_at_50 = ideal.rms_m[1];
      for (int k = 0; k < 3; ++k) EXPECT_LT(ideal.rms_m[k], 20e-6) << kDepths[k];
      EXPECT_LT(dynamic.rms_m[1], 100e-6);
    }
  }
  EXPECT_GT(rms_at_5, 5.0 * rms_at_50);
}

TEST_F(MemsScanPatternTest, AProjectionPlaneOnTheViewportBendsTheLines) {
  // The seed's projection plane is "arbitrary" for f1..f6, not for the pattern: lines straight
  // on the viewport's face fan out into curved surfaces (projection_functions.hpp).
  MemsScannerModel on_face = *model_;
  on_face.functions = SampleProjectionFunctions(on_face.laser, 41, 0.0);
  MemsScanPatternOptions options;
  options.lines = 11;
  options.waypoints_per_line = 50;
  const Planarity face =
      MeasurePlanarity(on_face, DesignMemsScanPattern(on_face.functions, options), false);
  const Planarity working =
      MeasurePlanarity(*model_, DesignMemsScanPattern(model_->functions, options), false);
  std::cout << "[ measured ] plane on the viewport: " << face.rms_m[1] * 1e6
            << " um rms at 1.25 m; at 1.3 m range: " << working.rms_m[1] * 1e6 << " um\n";
  EXPECT_GT(face.rms_m[1], 20.0 * working.rms_m[1]);
}

TEST_F(MemsScanPatternTest, TheFullRectangleNeedsMoreThanTheDriveRange) {
  // Eqs. 7-10 bound the FoV on the axes; its corners lie beyond the drive range (the beam's
  // footprint is not a rectangle), which must be an error naming the way out.
  MemsScanPatternOptions options;
  options.lines = 5;
  options.waypoints_per_line = 5;
  options.fov_fraction_x = 1.0;
  options.fov_fraction_y = 1.0;
  try {
    DesignMemsScanPattern(model_->functions, options);
    FAIL() << "designed a pattern outside the drive range";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("outside the calibrated range"), std::string::npos) << what;
    EXPECT_NE(what.find("lower fov_fraction"), std::string::npos) << what;
  }
}

TEST_F(MemsScanPatternTest, OptionsAreChecked) {
  MemsScanPatternOptions options;
  options.waypoints_per_line = 1;
  EXPECT_THROW(options.Check(), Error);
  options = {};
  options.lines = 0;
  EXPECT_THROW(options.Check(), Error);
  options = {};
  options.fov_fraction_x = 1.2;
  EXPECT_THROW(DesignMemsScanPattern(model_->functions, options), Error);
  options = {};
  options.plane_extension_m = 0.0;
  EXPECT_THROW(options.Check(), Error);
}

}  // namespace
}  // namespace uwscan::scanner
