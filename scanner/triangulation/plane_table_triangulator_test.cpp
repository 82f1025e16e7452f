#include "scanner/triangulation/plane_table_triangulator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <random>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/lasers/mems_scan_pattern.hpp"
#include "scanner/lasers/mems_scanner_model.hpp"

namespace uwscan::scanner {
namespace {

class PlaneTableTriangulatorTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    model_ = std::make_unique<MemsScannerModel>(DefaultMemsScannerModel());
    rays_ = std::make_shared<const CameraRayTable>(model_->camera, 2);
    MemsScanPatternOptions options;
    options.lines = 21;
    options.waypoints_per_line = 50;
    lines_ =
        std::make_unique<std::vector<MemsLine>>(DesignMemsScanPattern(model_->functions, options));
    std::vector<Plane> planes;
    for (const MemsLine& line : *lines_) planes.push_back(line.plane_C);
    triangulator_ = std::make_unique<PlaneTableTriangulator>(rays_, planes);
  }
  static void TearDownTestSuite() {
    triangulator_.reset();
    lines_.reset();
    rays_.reset();
    model_.reset();
  }
  static std::unique_ptr<MemsScannerModel> model_;
  static std::shared_ptr<const CameraRayTable> rays_;
  static std::unique_ptr<std::vector<MemsLine>> lines_;
  static std::unique_ptr<PlaneTableTriangulator> triangulator_;
};
std::unique_ptr<MemsScannerModel> PlaneTableTriangulatorTest::model_;
std::shared_ptr<const CameraRayTable> PlaneTableTriangulatorTest::rays_;
std::unique_ptr<std::vector<MemsLine>> PlaneTableTriangulatorTest::lines_;
std::unique_ptr<PlaneTableTriangulator> PlaneTableTriangulatorTest::triangulator_;

TEST_F(PlaneTableTriangulatorTest, PointsOnALinePlaneComeBack) {
  // Exact points on each line's plane over 0.6-1.5 m, seen through the camera viewport,
  // triangulated against that plane: only the camera-ray table's interpolation remains.
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> depth(0.6, 1.5), along(0.0, 1.0);
  double worst = 0.0;
  int seen = 0;
  for (std::size_t i = 0; i < lines_->size(); ++i) {
    const MemsLine& line = (*lines_)[i];
    std::vector<Eigen::Vector2d> px;
    std::vector<Eigen::Vector3d> truth;
    for (int k = 0; k < 200; ++k) {
      // A point of the line's light: a waypoint's beam at some depth, put exactly on the plane.
      const std::size_t j = static_cast<std::size_t>(along(rng) * (line.volts.size() - 1));
      const Ray beam = model_->functions.RayInWater_C(line.volts[j]).ray;
      Eigen::Vector3d p = beam.At((depth(rng) - beam.origin.z()) / beam.direction.z());
      p -= (line.plane_C.normal.dot(p) - line.plane_C.offset_m) * line.plane_C.normal;
      const std::optional<Eigen::Vector2d> uv = model_->camera.ProjectPointInWater(p);
      if (!uv || !model_->camera.camera.InImage(*uv)) continue;
      px.push_back(*uv);
      truth.push_back(p);
    }
    std::vector<TriangulatedPoint> out(px.size());
    triangulator_->TriangulateFrame(static_cast<int>(i), px, out);
    for (std::size_t k = 0; k < px.size(); ++k) {
      ASSERT_TRUE(out[k].ok()) << ToString(out[k].status);
      worst = std::max(worst, (out[k].p_C - truth[k]).norm());
    }
    seen += static_cast<int>(px.size());
  }
  std::cout << "[ measured ] plane-table triangulation of exact plane points: max error "
            << worst * 1e6 << " um over " << seen << " points\n";
  EXPECT_GT(seen, 1000);
  EXPECT_LT(worst, 1e-6);
}

TEST_F(PlaneTableTriangulatorTest, TrueLaserOnAWallComesBackWithinTheLinesFlatness) {
  // End to end on the true laser: the mirror's ideal path for a line lights a wall 1.25 m
  // away; its pixels triangulated against the line's plane land within the light's deviation
  // from that plane (tens of micrometres, mems_scan_pattern_test).
  const Plane wall{Eigen::Vector3d::UnitZ(), 1.25};
  double worst = 0.0, sum_sq = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < lines_->size(); ++i) {
    const TiltPath path = SimulateLine(model_->laser, (*lines_)[i].volts, model_->dynamics, false);
    std::vector<Eigen::Vector2d> px;
    std::vector<Eigen::Vector3d> truth;
    for (const TiltSample& s : path.samples) {
      const RayTrace beam = model_->laser.RayInWaterFromTilt(s.tilt_rad);
      const RayHit hit = IntersectRayPlane(beam.ray, wall);
      if (!hit.ok()) continue;
      const std::optional<Eigen::Vector2d> uv = model_->camera.ProjectPointInWater(hit.point);
      if (!uv || !model_->camera.camera.InImage(*uv)) continue;
      px.push_back(*uv);
      truth.push_back(hit.point);
    }
    std::vector<TriangulatedPoint> out(px.size());
    triangulator_->TriangulateFrame(static_cast<int>(i), px, out);
    for (std::size_t k = 0; k < px.size(); ++k) {
      ASSERT_TRUE(out[k].ok());
      const double e = (out[k].p_C - truth[k]).norm();
      worst = std::max(worst, e);
      sum_sq += e * e;
      ++count;
    }
  }
  std::cout << "[ measured ] true laser on a wall at 1.25 m: " << count << " points, error rms "
            << std::sqrt(sum_sq / count) * 1e3 << " mm, max " << worst * 1e3 << " mm\n";
  EXPECT_GT(count, 5000);
  EXPECT_LT(std::sqrt(sum_sq / count), 0.1e-3);
  EXPECT_LT(worst, 0.5e-3);
}

TEST_F(PlaneTableTriangulatorTest, MissesAreValues) {
  const std::vector<Eigen::Vector2d> px = {{1000.0, 500.0}, {-10.0, 500.0}};
  std::vector<TriangulatedPoint> out(px.size());
  for (const int step : {-1, static_cast<int>(lines_->size())}) {
    triangulator_->TriangulateFrame(step, px, out);
    for (const TriangulatedPoint& p : out) EXPECT_EQ(p.status, HitStatus::kOutsideSurface);
  }
  triangulator_->TriangulateFrame(3, px, out);
  EXPECT_TRUE(out[0].ok());
  EXPECT_EQ(out[1].status, HitStatus::kNoIntersection);  // outside the image

  // A plane containing the camera ray is parallel to it; a plane behind the camera is behind.
  Ray ray;
  ASSERT_TRUE(rays_->Lookup(1000.0, 500.0, &ray));
  const Eigen::Vector3d n = ray.direction.cross(Eigen::Vector3d::UnitY()).normalized();
  const PlaneTableTriangulator special(
      rays_, {Plane{n, n.dot(ray.origin)}, Plane{Eigen::Vector3d::UnitZ(), -1.0}});
  const std::vector<Eigen::Vector2d> one = {{1000.0, 500.0}};
  std::vector<TriangulatedPoint> result(1);
  special.TriangulateFrame(0, one, result);
  EXPECT_EQ(result[0].status, HitStatus::kParallel);
  special.TriangulateFrame(1, one, result);
  EXPECT_EQ(result[0].status, HitStatus::kBehind);
}

TEST_F(PlaneTableTriangulatorTest, RejectsBadConstruction) {
  EXPECT_THROW(PlaneTableTriangulator(nullptr, {}), Error);
  EXPECT_THROW(PlaneTableTriangulator(rays_, {Plane{Eigen::Vector3d(0.0, 0.0, 2.0), 1.0}}), Error);
  EXPECT_THROW(PlaneTableTriangulator(rays_, {Plane{Eigen::Vector3d::UnitZ(), std::nan("")}}),
               Error);
  TriangulationOptions options;
  options.min_angle_rad = -1.0;
  EXPECT_THROW(PlaneTableTriangulator(rays_, {}, options), Error);
}

}  // namespace
}  // namespace uwscan::scanner
