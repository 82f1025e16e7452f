#include "perception/recognition/recognition_verification.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace uwscan::perception {
namespace {

// A sensor at the origin looking along +z over a seabed at 1 m; a square plate 100 mm wide,
// facing the sensor, may stand 100 mm above the seabed (at 0.9 m).
constexpr double kSeabedZ = 1.0, kPlateZ = 0.9, kPlateHalf = 0.05, kRadius = 0.01;

// Where a line of sight towards (u, v, 1) first meets the scene; the plate there spans x up to
// `plate_to_x`.
Eigen::Vector3d Hit(double u, double v, bool plate, double plate_to_x) {
  const Eigen::Vector3d on_plate = kPlateZ * Eigen::Vector3d(u, v, 1.0);
  if (plate && on_plate.x() >= -kPlateHalf && on_plate.x() <= plate_to_x && std::abs(on_plate.y()) <= kPlateHalf) {
    return on_plate;
  }
  return kSeabedZ * Eigen::Vector3d(u, v, 1.0);
}

// A scan of laser lines along u, `line_spacing` apart in v (at 1 m), sampled every 2 mm along
// each line.
PointCloud Scan(bool plate, double line_spacing, double plate_to_x = kPlateHalf) {
  std::vector<Eigen::Vector3d> points;
  for (double v = -0.2; v <= 0.2 + 1e-9; v += line_spacing) {
    for (double u = -0.2; u <= 0.2 + 1e-9; u += 0.002) points.push_back(Hit(u, v, plate, plate_to_x));
  }
  return MakeCloud(points);
}

// The plate model: a 5 mm grid in its own z = 0 plane, its normal towards the sensor (-z).
ObjectModel Plate() {
  ObjectModel o;
  o.id = "plate";
  std::vector<Eigen::Vector3d> points;
  for (double x = -kPlateHalf; x <= kPlateHalf + 1e-9; x += 0.005) {
    for (double y = -kPlateHalf; y <= kPlateHalf + 1e-9; y += 0.005) points.emplace_back(x, y, 0.0);
  }
  o.model = MakeCloud(points);
  o.model.normals.assign(points.size(), Eigen::Vector3f(0.0f, 0.0f, -1.0f));
  return o;
}

double Missing(const PointCloud& scan, const Eigen::Isometry3d& T_S_O) {
  const ObjectModel plate = Plate();
  const KnnIndex index(scan.points);
  // The segment's window: where the plate would be.
  const SceneAround around = SceneAroundSegment(scan, index, Transformed(plate.model, T_S_O), kRadius);
  return MissingShare(plate, T_S_O, around, kRadius);
}

const Eigen::Isometry3d kOnPlate(Eigen::Translation3d(0.0, 0.0, kPlateZ));

TEST(MissingShareTest, APlateTheScanSawIsNotMissing) {
  EXPECT_EQ(Missing(Scan(true, 0.004), kOnPlate), 0.0);
}

TEST(MissingShareTest, APlateTheSensorSawThroughIsMissing) {
  EXPECT_GT(Missing(Scan(false, 0.004), kOnPlate), 0.95);
}

// Laser lines 30 mm apart leave most of the plate between them, unseen but not seen through:
// that is no evidence against it. Where the lines cross an absent plate, it is missing.
TEST(MissingShareTest, SurfaceBetweenLaserLinesIsNoEvidence) {
  EXPECT_EQ(Missing(Scan(true, 0.03), kOnPlate), 0.0);
  EXPECT_GT(Missing(Scan(false, 0.03), kOnPlate), 0.95);
}

// Posed 5 mm in front of the seabed the plate is on what the sensor saw (within the seen
// radius), not seen through; posed 50 mm in front of the seabed, it is.
TEST(MissingShareTest, SeeingThroughNeedsTheLineOfSightToEndBeyondTheSurface) {
  const PointCloud seabed_only = Scan(false, 0.004);
  EXPECT_EQ(Missing(seabed_only, Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, kSeabedZ - 0.005))), 0.0);
  EXPECT_GT(Missing(seabed_only, Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, kSeabedZ - 0.05))), 0.95);
}

// Half the plate seen, the sensor seeing the seabed where the other half should be.
TEST(MissingShareTest, HalfAPlateIsHalfMissing) {
  EXPECT_NEAR(Missing(Scan(true, 0.004, 0.0), kOnPlate), 0.5, 0.1);
}

}  // namespace
}  // namespace uwscan::perception
