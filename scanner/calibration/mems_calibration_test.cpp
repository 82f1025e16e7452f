#include "scanner/calibration/mems_calibration.hpp"

#include <gtest/gtest.h>

#include <iostream>
#include <random>

#include "scanner/common/error.hpp"
#include "scanner/lasers/mems_scanner_model.hpp"

namespace uwscan::scanner::calibration {
namespace {

Plane PlaneAt(double depth_m, double tilt_rad) {
  Plane plane;
  plane.normal = Eigen::Vector3d(std::sin(tilt_rad), 0.0, -std::cos(tilt_rad));
  plane.offset_m = plane.normal.dot(Eigen::Vector3d(0.0, 0.0, depth_m));
  if (plane.offset_m < 0) {
    plane.normal = -plane.normal;
    plane.offset_m = -plane.offset_m;
  }
  return plane;
}

struct Dataset {
  std::vector<Plane> planes;
  std::vector<std::vector<DotObservation>> dots;
};

// The true laser's dots on planes at 0.8-1.6 m, as the camera sees them, with pixel noise.
Dataset MakeDataset(const MemsScannerModel& truth, double noise_px, double volts_scale,
                    std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_px);
  Dataset d;
  const double depths[] = {0.8, 1.0, 1.2, 1.4, 1.6};
  const double tilts[] = {0.1, -0.15, 0.0, 0.2, -0.05};
  for (int l = 0; l < 5; ++l) {
    d.planes.push_back(PlaneAt(depths[l], tilts[l]));
    d.dots.emplace_back();
    for (int i = 0; i < 9; ++i) {
      for (int j = 0; j < 9; ++j) {
        const Eigen::Vector2d volts(-9.0 + 2.25 * i, -9.0 + 2.25 * j);
        const RayTrace beam = truth.laser.RayInWater(volts);
        const RayHit hit = IntersectRayPlane(beam.ray, d.planes.back());
        if (!beam.ok() || !hit.ok()) continue;
        const std::optional<Eigen::Vector2d> px = truth.camera.ProjectPointInWater(hit.point);
        if (!px || !truth.camera.camera.InImage(*px)) continue;
        DotObservation dot;
        dot.volts = volts * volts_scale;
        dot.dot_px = *px + (noise_px > 0 ? Eigen::Vector2d{noise(rng), noise(rng)}
                                         : Eigen::Vector2d::Zero());
        d.dots.back().push_back(dot);
      }
    }
  }
  return d;
}

// Largest distance between the fitted and the true beam at depths 0.8 and 1.5 m, at the
// calibrated voltage pairs and half-way between neighbouring ones (no extrapolation).
double WorstBeamError(const MemsScannerModel& truth, const MemsCalibrationResult& r,
                      double volts_scale) {
  std::vector<Eigen::Vector2d> probes;
  for (const VoltageLine& a : r.lines) {
    probes.push_back(a.volts / volts_scale);
    for (const VoltageLine& b : r.lines) {
      if ((a.volts - b.volts).norm() / volts_scale < 2.3)
        probes.push_back(0.5 * (a.volts + b.volts) / volts_scale);
    }
  }
  double worst = 0.0;
  for (const Eigen::Vector2d& volts : probes) {
    const RayTrace t = truth.laser.RayInWater(volts);
    const RayTrace e = r.functions.RayInWater_C(volts * volts_scale);
    if (!t.ok() || !e.ok()) continue;
    for (const double depth : {0.8, 1.5}) {
      const Eigen::Vector3d pt = t.ray.At((depth - t.ray.origin.z()) / t.ray.direction.z());
      const Eigen::Vector3d pe = e.ray.At((depth - e.ray.origin.z()) / e.ray.direction.z());
      worst = std::max(worst, (pt - pe).norm());
    }
  }
  return worst;
}

TEST(MemsCalibration, ExactDotsRecoverTheBeams) {
  const MemsScannerModel truth = DefaultMemsScannerModel();
  const Dataset d = MakeDataset(truth, 0.0, 1.0, 1);
  const MemsCalibrationResult r = CalibrateMemsProjection(truth.camera, d.planes, d.dots);
  EXPECT_GE(r.lines.size(), 40u);  // the pairs the camera sees on at least two planes
  EXPECT_LT(r.line_rms_m, 1e-9);
  for (const FitErrorStats& e : r.errors) EXPECT_LT(e.max_percent, 0.1);
  // Limited by how well degree-5 polynomials follow the true optics (sub-0.1 mm).
  const double worst = WorstBeamError(truth, r, 1.0);
  std::cout << "[ measured ] exact dots: " << r.lines.size() << " lines, worst beam error "
            << worst * 1e3 << " mm, f1..f6 max % error " << r.errors[0].max_percent << " "
            << r.errors[1].max_percent << " " << r.errors[2].max_percent << " "
            << r.errors[3].max_percent << " " << r.errors[4].max_percent << " "
            << r.errors[5].max_percent << "\n";
  EXPECT_LT(worst, 2e-4);
}

TEST(MemsCalibration, NoisyDotsStaySubMillimetre) {
  const MemsScannerModel truth = DefaultMemsScannerModel();
  const Dataset d = MakeDataset(truth, 0.2, 1.0, 2);
  const MemsCalibrationResult r = CalibrateMemsProjection(truth.camera, d.planes, d.dots);
  EXPECT_LT(r.line_rms_m, 5e-4);
  const double worst = WorstBeamError(truth, r, 1.0);
  std::cout << "[ measured ] 0.2 px dot noise: line rms " << r.line_rms_m * 1e3
            << " mm, worst beam error " << worst * 1e3 << " mm\n";
  EXPECT_LT(worst, 1e-3);
}

TEST(MemsCalibration, VoltsAndMillivoltsGiveTheSameBeams) {
  const MemsScannerModel truth = DefaultMemsScannerModel();
  const Dataset volts = MakeDataset(truth, 0.2, 1.0, 3);
  const Dataset millivolts = MakeDataset(truth, 0.2, 1000.0, 3);
  const ProjectionFunctions a =
      CalibrateMemsProjection(truth.camera, volts.planes, volts.dots).functions;
  const ProjectionFunctions b =
      CalibrateMemsProjection(truth.camera, millivolts.planes, millivolts.dots).functions;
  for (const Eigen::Vector2d& v : {Eigen::Vector2d(0.3, -4.0), Eigen::Vector2d(7.9, 8.1)}) {
    const RayTrace ra = a.RayInWater_C(v);
    const RayTrace rb = b.RayInWater_C(1000.0 * v);
    ASSERT_TRUE(ra.ok() && rb.ok());
    EXPECT_LT((ra.ray.origin - rb.ray.origin).norm(), 1e-9);
    EXPECT_LT((ra.ray.direction - rb.ray.direction).norm(), 1e-9);
  }
}

TEST(MemsCalibration, BadDatasetsNameTheProblem) {
  const MemsScannerModel truth = DefaultMemsScannerModel();
  Dataset d = MakeDataset(truth, 0.0, 1.0, 4);
  EXPECT_THROW(CalibrateMemsProjection(truth.camera, {d.planes[0]}, {d.dots[0]}), Error);
  Dataset twice = d;
  twice.dots[1].push_back(twice.dots[1].front());
  EXPECT_THROW(CalibrateMemsProjection(truth.camera, twice.planes, twice.dots), Error);
  Dataset few = d;
  for (auto& plane_dots : few.dots) plane_dots.resize(10);
  EXPECT_THROW(CalibrateMemsProjection(truth.camera, few.planes, few.dots), Error);
  d.dots[0][0].dot_px.x() = std::nan("");
  EXPECT_THROW(CalibrateMemsProjection(truth.camera, d.planes, d.dots), Error);
}

}  // namespace
}  // namespace uwscan::scanner::calibration
