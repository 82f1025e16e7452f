#include "mapping/reconstruction/scan_file.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "mapping/log/dive_log_test_support.hpp"
#include "mapping/log/dive_simulation.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "perception/recognition/recognition_test_support.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"

namespace uwscan::mapping::test {
namespace {

class ScanFileTest : public DiveLogTest {
 protected:
  // The short inspection dive's first four sweeps, the vehicle moving 0.2 m/s, navigation exact.
  fs::path MovingDive() {
    scanner::sim::Scene scene = scanner::sim::LoadScene(fs::path(UWSCAN_SOURCE_DIR_FOR_TESTS) /
                                                        "data/scenes/inspection_short.yaml");
    scene.scanner.sweeps = 4;
    scene.effects.navigation_drift.on = false;
    scene.effects.peak_noise.on = false;
    const fs::path path = dir_ / "moving.db";
    const scanner::sim::Simulator simulator(scene);
    DiveSimulationOptions options;
    options.threads = 2;
    SimulateDive(simulator, "", path, options);
    return path;
  }
};

TEST_F(ScanFileTest, ACloudFileSaysWhichRowEachFinitePointCameFrom) {
  const fs::path path = dir_ / "holes.xyz";
  {
    std::ofstream out(path);
    out << "0 0 1\nnan 0 1\n0.1 0 1\n0 inf 1\n0.2 0 1\n";
  }
  const ScanFile scan = ReadScanFile(path);
  ASSERT_EQ(scan.cloud.size(), 3u);
  EXPECT_EQ(scan.rows, (std::vector<std::size_t>{0, 2, 4}));
  EXPECT_EQ(scan.rows_in_file, 5u);
  EXPECT_NEAR(scan.cloud.Point(1).x(), 0.1, 1e-6);

  ReconstructionOptions options;
  options.sweep = 0;
  EXPECT_NE(MessageOf([&] { ReadScanFile(path, options); }).find("this is a cloud file"),
            std::string::npos);
}

// An ascii PCD of `points` scaled by `units_per_metre`, with a VIEWPOINT line when `viewpoint`
// is given ("tx ty tz qw qx qy qz", PCL's order).
void WritePcd(const fs::path& path, const std::vector<Eigen::Vector3d>& points,
              double units_per_metre, const std::string& viewpoint = "") {
  std::ofstream out(path);
  out.precision(10);
  out << "VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " << points.size()
      << "\nHEIGHT 1\n";
  if (!viewpoint.empty()) out << "VIEWPOINT " << viewpoint << "\n";
  out << "POINTS " << points.size() << "\nDATA ascii\n";
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d q = units_per_metre * p;
    out << q.x() << " " << q.y() << " " << q.z() << "\n";
  }
}

// A patch 0.4 m wide, 1 m in front of the sensor (+z).
std::vector<Eigen::Vector3d> Patch() {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 40; ++i) {
    for (int k = 0; k < 40; ++k) points.emplace_back(0.01 * i - 0.2, 0.01 * k - 0.2, 1.0);
  }
  return points;
}

TEST_F(ScanFileTest, AScanInMillimetresIsReadInMetresWithItsUnitAndRefusedWithoutIt) {
  const std::vector<Eigen::Vector3d> truth = Patch();
  const fs::path mm = dir_ / "patch_mm.pcd", m = dir_ / "patch_m.pcd";
  WritePcd(mm, truth, 1000.0);
  WritePcd(m, truth, 1.0);
  ScanFrame frame;
  frame.metres_per_unit = 0.001;
  const ScanFile scan = ReadScanFile(mm, {}, frame);
  ASSERT_EQ(scan.cloud.size(), truth.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    EXPECT_LT((scan.cloud.Point(i) - truth[i]).norm(), 1e-6) << i;
  }
  EXPECT_EQ(scan.metres_per_unit, 0.001);
  EXPECT_EQ(scan.viewpoint, ViewpointSource::kFileOrigin);

  // Without its unit: 1.4 km across, which no scan is; a scan in metres said to be in mm is
  // 1.4 mm across.
  EXPECT_NE(MessageOf([&] { ReadScanFile(mm); }).find("is it in millimetres? give --units mm"),
            std::string::npos)
      << MessageOf([&] { ReadScanFile(mm); });
  EXPECT_NE(MessageOf([&] { ReadScanFile(m, {}, frame); }).find("is it in metres? give --units m"),
            std::string::npos)
      << MessageOf([&] { ReadScanFile(m, {}, frame); });
}

TEST_F(ScanFileTest, APcdViewpointPutsTheScanInTheSensorsFrameUnlessAnotherIsGiven) {
  // The sensor 2 m above the file's origin looking down (-z), turned 30 degrees about z: a depth
  // camera's frame that looks along -z, as many range scanners' do.
  Eigen::Isometry3d T_file_sensor = Eigen::Isometry3d::Identity();
  T_file_sensor.linear() = (Eigen::AngleAxisd(0.5236, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()))
                               .toRotationMatrix();
  T_file_sensor.translation() = Eigen::Vector3d(0.3, -0.1, 2.0);
  const std::vector<Eigen::Vector3d> in_sensor = Patch();
  std::vector<Eigen::Vector3d> in_file;
  for (const Eigen::Vector3d& p : in_sensor) in_file.push_back(T_file_sensor * p);
  const Eigen::Quaterniond q(T_file_sensor.linear());
  std::ostringstream viewpoint;
  viewpoint.precision(17);
  viewpoint << 300.0 << " " << -100.0 << " " << 2000.0 << " " << q.w() << " " << q.x() << " "
            << q.y() << " " << q.z();
  const fs::path path = dir_ / "depth_camera_mm.pcd";
  WritePcd(path, in_file, 1000.0, viewpoint.str());

  ScanFrame frame;
  frame.metres_per_unit = 0.001;
  const ScanFile scan = ReadScanFile(path, {}, frame);
  EXPECT_EQ(scan.viewpoint, ViewpointSource::kFileViewpoint);
  EXPECT_LT((scan.T_file_sensor.translation() - Eigen::Vector3d(300, -100, 2000)).norm(), 1e-9);
  ASSERT_EQ(scan.cloud.size(), in_sensor.size());
  for (std::size_t i = 0; i < in_sensor.size(); ++i) {
    EXPECT_LT((scan.cloud.Point(i) - in_sensor[i]).norm(), 1e-6) << i;
  }

  // A viewpoint given overrides the file's: the sensor at the file's origin, axes unturned.
  frame.T_file_sensor = Eigen::Isometry3d::Identity();
  const ScanFile given = ReadScanFile(path, {}, frame);
  EXPECT_EQ(given.viewpoint, ViewpointSource::kGiven);
  for (std::size_t i = 0; i < in_file.size(); ++i) {
    EXPECT_LT((given.cloud.Point(i) - in_file[i]).norm(), 1e-6) << i;
  }

  // A malformed VIEWPOINT is named when the file's viewpoint would be used, and does not matter
  // when one is given (other readers of the cloud never look at it).
  WritePcd(path, in_file, 1000.0, "0 0 0 0 0 0 0");
  ScanFrame mm;
  mm.metres_per_unit = 0.001;
  EXPECT_NE(MessageOf([&] {
              ReadScanFile(path, {}, mm);
            }).find("(VIEWPOINT): the orientation quaternion has zero length"),
            std::string::npos)
      << MessageOf([&] { ReadScanFile(path, {}, mm); });
  EXPECT_EQ(ReadScanFile(path, {}, frame).cloud.size(), in_file.size());
  EXPECT_EQ(perception::ReadCloud(path).size(), in_file.size());
  WritePcd(path, in_file, 1000.0, "0 0 0 1 0 0");
  EXPECT_NE(MessageOf([&] { ReadScanFile(path, {}, mm); }).find("(VIEWPOINT): expected 7 numbers"),
            std::string::npos);
  WritePcd(path, in_file, 1000.0, "+300 -100 +2000 1 0 0 0");  // a '+' as other tools write it
  EXPECT_EQ(ReadScanFile(path, {}, mm).viewpoint, ViewpointSource::kFileViewpoint);
}

// The same scene as recognition's tests scan it, written as another tool would: in millimetres,
// in a frame the sensor is not at the origin of, the sensor's pose in the PCD's VIEWPOINT. Read
// with its unit, it is recognised as the scan in metres from the origin is: the same object, the
// same pose once put back in the sensor's frame.
TEST_F(ScanFileTest, AScanInMillimetresFromAViewpointIsRecognisedAsInMetresFromTheOrigin) {
  namespace rt = perception::recognition_test;
  const rt::Scan scan = rt::ScanOnSeabed(scanner::sim::MakeFlange(scanner::sim::FlangeShape{}),
                                         Eigen::Vector3d(0.5, -0.4, 0.9), 3);
  Eigen::Isometry3d T_file_sensor = Eigen::Isometry3d::Identity();
  T_file_sensor.linear() =
      Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  T_file_sensor.translation() = Eigen::Vector3d(12.0, -3.0, 40.0);
  std::vector<Eigen::Vector3d> in_file, in_sensor;
  for (std::size_t i = 0; i < scan.cloud.size(); ++i) {
    in_sensor.push_back(scan.cloud.Point(i));
    in_file.push_back(T_file_sensor * in_sensor.back());
  }
  const Eigen::Quaterniond q(T_file_sensor.linear());
  std::ostringstream viewpoint;
  viewpoint.precision(17);
  viewpoint << 12000.0 << " " << -3000.0 << " " << 40000.0 << " " << q.w() << " " << q.x() << " "
            << q.y() << " " << q.z();
  const fs::path path = dir_ / "flange_mm.pcd", reference = dir_ / "flange_m.pcd";
  WritePcd(path, in_file, 1000.0, viewpoint.str());
  WritePcd(reference, in_sensor, 1.0);
  ScanFrame frame;
  frame.metres_per_unit = 0.001;
  const perception::ObjectDatabase& db = rt::PipeFlangeValveDb();
  const perception::RecognitionResult moved =
      perception::RecognizeObjects(ReadScanFile(path, {}, frame).cloud, db);
  const perception::RecognitionResult original =
      perception::RecognizeObjects(ReadScanFile(reference).cloud, db);
  const perception::RecognizedObject* a = rt::Nearest(moved, scan);
  const perception::RecognizedObject* b = rt::Nearest(original, scan);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->object_id, "flange");
  EXPECT_EQ(a->object_id, b->object_id);
  const Eigen::Isometry3d d = a->T_S_O.inverse() * b->T_S_O;
  EXPECT_LT(d.translation().norm(), 1e-3);
  EXPECT_LT(Eigen::AngleAxisd(d.linear()).angle(), 0.2 * M_PI / 180.0);
}

// A sweep taken while the vehicle moves 10 cm: each frame placed with the navigation, the
// points in the camera frame at the sweep's middle lie on the true surfaces there; stacked as
// if the scanner had stood still (what a cloud in the camera frame of each frame gives), they
// would be smeared by the motion.
TEST_F(ScanFileTest, ASweepOfAMovingDiveIsPlacedWithItsNavigation) {
  const fs::path path = MovingDive();
  EXPECT_NE(MessageOf([&] {
              ReadScanFile(path);
            }).find("holds 4 sweeps, 0 to 3; recognition takes one: choose it with --sweep"),
            std::string::npos)
      << MessageOf([&] { ReadScanFile(path); });
  ReconstructionOptions options;
  options.sweep = 7;
  EXPECT_NE(MessageOf([&] {
              ReadScanFile(path, options);
            }).find("has no sweep 7 (it holds 4 sweeps, 0 to 3)"),
            std::string::npos);

  options.sweep = 2;
  const ScanFile scan = ReadScanFile(path, options);
  const DiveLogReader log(path);
  options.use_navigation = true;
  options.relative_to_middle = true;
  const Reconstruction placed = Reconstruct(log, options);
  ASSERT_EQ(placed.truth.size(), scan.cloud.size());
  ASSERT_GT(scan.cloud.size(), 10000u);
  options.use_navigation = false;  // each frame in its own camera frame, as if at rest
  const Reconstruction at_rest = Reconstruct(log, options);
  ASSERT_EQ(at_rest.points.size(), scan.cloud.size());
  double worst_placed_m = 0.0, worst_at_rest_m = 0.0;
  for (std::size_t i = 0; i < scan.cloud.size(); ++i) {
    if (!placed.truth[i].allFinite()) continue;
    EXPECT_EQ(placed.frame_of_point[i], at_rest.frame_of_point[i]);
    worst_placed_m = std::max(worst_placed_m, (scan.cloud.Point(i) - placed.truth[i]).norm());
    worst_at_rest_m = std::max(worst_at_rest_m, (at_rest.points[i] - placed.truth[i]).norm());
  }
  EXPECT_LT(worst_placed_m, 1e-4);
  EXPECT_GT(worst_at_rest_m, 0.02);
  for (std::int64_t frame : placed.frame_of_point) EXPECT_EQ(log.ReadFrame(frame).sweep, 2);
}

}  // namespace
}  // namespace uwscan::mapping::test
