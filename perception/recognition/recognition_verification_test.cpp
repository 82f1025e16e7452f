#include "perception/recognition/recognition_verification.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

// A sensor at the origin looking along +z over a seabed at 1 m; a square plate 100 mm wide,
// facing the sensor, may stand 100 mm above the seabed (at 0.9 m).
constexpr double kSeabedZ = 1.0, kPlateZ = 0.9, kPlateHalf = 0.05, kRadius = 0.01;

// Where a line of sight towards (u, v, 1) first meets the scene; the plate there spans x up to
// `plate_to_x`.
Eigen::Vector3d Hit(double u, double v, bool plate, double plate_to_x) {
  const Eigen::Vector3d on_plate = kPlateZ * Eigen::Vector3d(u, v, 1.0);
  if (plate && on_plate.x() >= -kPlateHalf && on_plate.x() <= plate_to_x &&
      std::abs(on_plate.y()) <= kPlateHalf) {
    return on_plate;
  }
  return kSeabedZ * Eigen::Vector3d(u, v, 1.0);
}

// A scan of laser lines along u, `line_spacing` apart in v (at 1 m), sampled every 2 mm along
// each line.
PointCloud Scan(bool plate, double line_spacing, double plate_to_x = kPlateHalf) {
  std::vector<Eigen::Vector3d> points;
  for (double v = -0.2; v <= 0.2 + 1e-9; v += line_spacing) {
    for (double u = -0.2; u <= 0.2 + 1e-9; u += 0.002)
      points.push_back(Hit(u, v, plate, plate_to_x));
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

SceneAround Around(const PointCloud& scan, const KnnIndex& index, const Eigen::Isometry3d& T_S_O) {
  // The segment's window: where the plate would be.
  return SceneAroundSegment(scan, index, Transformed(Plate().model, T_S_O), kRadius);
}

double Missing(const PointCloud& scan, const Eigen::Isometry3d& T_S_O) {
  const KnnIndex index(scan.points);
  return MissingShare(Plate(), T_S_O, Around(scan, index, T_S_O), kRadius);
}

const Eigen::Isometry3d kOnPlate(Eigen::Translation3d(0.0, 0.0, kPlateZ));
const Eigen::Vector3d kTowardsSensor(0.0, 0.0, -1.0);

// Whether the scan saw through the plate's surface at (x, y) of the plate.
bool SeenThrough(const PointCloud& scan, double x, double y) {
  const KnnIndex index(scan.points);
  return Around(scan, index, kOnPlate)
      .SeenThrough(Eigen::Vector3d(x, y, kPlateZ), kTowardsSensor, 0.5 * kRadius, 0.5 * kRadius);
}

TEST(MissingShareTest, APlateTheScanSawIsNotMissing) {
  EXPECT_EQ(Missing(Scan(true, 0.004), kOnPlate), 0.0);
  EXPECT_FALSE(SeenThrough(Scan(true, 0.004), 0.0, 0.0));
}

TEST(MissingShareTest, APlateTheSensorSawThroughIsMissing) {
  EXPECT_TRUE(SeenThrough(Scan(false, 0.004), 0.0, 0.0));
  EXPECT_GT(Missing(Scan(false, 0.004), kOnPlate), 0.95);
}

// Laser lines 30 mm apart (27 mm at the plate) leave most of the plate between them, unseen but
// not seen through: that is no evidence against it. Where the lines cross an absent plate, it is
// missing.
TEST(MissingShareTest, SurfaceBetweenLaserLinesIsNoEvidence) {
  EXPECT_EQ(Missing(Scan(true, 0.03), kOnPlate), 0.0);
  const PointCloud no_plate = Scan(false, 0.03);
  EXPECT_TRUE(SeenThrough(no_plate, 0.0, 0.009));    // on the line v = 0.01 (y = 0.9 v there)
  EXPECT_FALSE(SeenThrough(no_plate, 0.0, 0.0225));  // half-way to the next, v = 0.04
  EXPECT_GT(Missing(no_plate, kOnPlate), 0.95);
}

// Half the plate seen, the sensor seeing the seabed where the other half should be.
TEST(MissingShareTest, HalfAPlateIsHalfMissing) {
  EXPECT_NEAR(Missing(Scan(true, 0.004, 0.0), kOnPlate), 0.5, 0.1);
}

// A plate posed 5 mm in front of the seabed lies on what the sensor saw (within the seen radius);
// posed 50 mm in front of it, the sensor saw through it.
TEST(MissingShareTest, APlateJustInFrontOfWhatTheScanSawIsSeen) {
  const PointCloud seabed_only = Scan(false, 0.004);
  EXPECT_EQ(
      Missing(seabed_only, Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, kSeabedZ - 0.005))),
      0.0);
  EXPECT_GT(
      Missing(seabed_only, Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, kSeabedZ - 0.05))),
      0.95);
}

// Seen through means the line of sight ends more than `beyond_m` past the surface's plane (along
// the line, not the normal), and passes within `lateral_m` of the point.
TEST(MissingShareTest, SeenThroughNeedsTheLineOfSightToEndBeyondTheSurfaceNearThePoint) {
  const Eigen::Vector3d p(0.02, 0.0, 1.0);  // the one scan point, 1 m away
  const PointCloud scan = MakeCloud(std::vector<Eigen::Vector3d>{p});
  const KnnIndex index(scan.points);
  const SceneAround around = SceneAroundSegment(scan, index, scan, kRadius, 0.05);
  // A surface facing the sensor, 30 mm (along the line of sight) in front of the point.
  const Eigen::Vector3d x = (1.0 - 0.03) * p;
  EXPECT_TRUE(around.SeenThrough(x, kTowardsSensor, 0.001, 0.02));
  EXPECT_FALSE(around.SeenThrough(x, kTowardsSensor, 0.001, 0.04));
  // 3 mm beside the line of sight.
  const Eigen::Vector3d beside = x + Eigen::Vector3d(0.0, 0.003, 0.0);
  EXPECT_TRUE(around.SeenThrough(beside, kTowardsSensor, 0.005, 0.02));
  EXPECT_FALSE(around.SeenThrough(beside, kTowardsSensor, 0.002, 0.02));
}

TEST(MissingShareTest, AnEmptySegmentIsRefused) {
  const PointCloud scan = Scan(true, 0.004);
  const KnnIndex index(scan.points);
  EXPECT_THROW(SceneAroundSegment(scan, index, PointCloud{}, kRadius), Error);
}

// The seabed plane of the scan above, as plane removal gives it (its normal away from the sensor,
// n . x + offset = 0), with every seabed point of a scan without the plate as its inliers.
DetectedPlane Seabed(const PointCloud& scan) {
  DetectedPlane seabed{Eigen::Vector3d::UnitZ(), -kSeabedZ, {}};
  for (std::size_t i = 0; i < scan.size(); ++i) seabed.inliers.push_back(i);
  return seabed;
}

// The plane is turned to face the sensor; a plane with too few inliers near the segment is not
// its support.
TEST(SupportContact, TheSeabedAroundASegmentFacesTheSensor) {
  const PointCloud scan = Scan(false, 0.01);
  const std::vector<SupportPlane> around =
      SupportPlanesAround(scan, {Seabed(scan)}, Eigen::Vector3d(0.0, 0.0, kSeabedZ), 0.05, 20);
  ASSERT_EQ(around.size(), 1u);
  EXPECT_NEAR(around[0].normal.z(), -1.0, 1e-12);
  EXPECT_NEAR(around[0].offset_m, kSeabedZ, 1e-12);
  EXPECT_GT(around[0].normal.dot(Eigen::Vector3d::Zero()) + around[0].offset_m, 0.0)
      << "the sensor's side";
  EXPECT_TRUE(
      SupportPlanesAround(scan, {Seabed(scan)}, Eigen::Vector3d(2.0, 0.0, kSeabedZ), 0.05, 20)
          .empty());
}

// The plate stood on its edge across the seabed, sunk by `sunk_m`: its buried share is the share
// of its points deeper than the tolerance (counted here from their z), and its clearance the
// depth of its deepest point, negated.
TEST(SupportContact, APlateSunkIntoTheSeabedIsBuriedByItsShareBelowIt) {
  const PointCloud scan = Scan(false, 0.01);
  const std::vector<SupportPlane> planes =
      SupportPlanesAround(scan, {Seabed(scan)}, Eigen::Vector3d(0.0, 0.0, kSeabedZ), 0.1, 20);
  const ObjectModel plate = Plate();
  for (const double sunk_m : {-0.02, 0.0, 0.03, kPlateHalf}) {
    // Plate y -> sensor z: its edge at y = +kPlateHalf is the lowest, sunk_m below the seabed.
    Eigen::Isometry3d T_S_O = Eigen::Isometry3d::Identity();
    T_S_O.linear() << 1, 0, 0, 0, 0, -1, 0, 1, 0;
    T_S_O.translation() = Eigen::Vector3d(0.0, 0.0, kSeabedZ + sunk_m - kPlateHalf);
    std::size_t deeper = 0;
    for (std::size_t i = 0; i < plate.model.size(); ++i)
      deeper += (T_S_O * plate.model.Point(i)).z() > kSeabedZ + 0.01 ? 1 : 0;
    const SupportContact contact = SupportContactOf(plate, T_S_O, planes, 0.01);
    EXPECT_DOUBLE_EQ(contact.buried,
                     static_cast<double>(deeper) / static_cast<double>(plate.model.size()))
        << sunk_m;
    EXPECT_NEAR(contact.clearance_m, -sunk_m, 1e-9) << sunk_m;
  }
  EXPECT_GT(SupportContactOf(plate, Eigen::Isometry3d(Eigen::Translation3d(0, 0, kSeabedZ + 0.04)),
                             planes, 0.01)
                .buried,
            0.99);
  const SupportContact no_plane = SupportContactOf(plate, Eigen::Isometry3d::Identity(), {}, 0.01);
  EXPECT_EQ(no_plane.buried, 0.0);
  EXPECT_TRUE(std::isinf(no_plane.clearance_m));
}

}  // namespace
}  // namespace uwscan::perception
