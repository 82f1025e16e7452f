#include "mapping/change/compare_surveys.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <random>

#include "scanner/common/error.hpp"
#include "scanner/common/triangle_mesh.hpp"
#include "scanner/sim/imr_objects.hpp"

namespace uwscan::mapping {
namespace {

using perception::PointCloud;

// A seabed (1.2 m square at 10 m, NED) with a box and a half-buried sphere on it: enough relief
// to pin a registration in every direction.
scanner::TriangleMesh Structure() {
  scanner::TriangleMesh out;
  const auto add = [&out](const scanner::TriangleMesh& mesh, const Eigen::Isometry3d& T) {
    const int first = static_cast<int>(out.vertices.size());
    for (const Eigen::Vector3d& v : mesh.vertices) out.vertices.push_back(T * v);
    for (const Eigen::Vector3i& t : mesh.triangles) out.triangles.push_back(t.array() + first);
  };
  Eigen::Isometry3d seabed = Eigen::Isometry3d::Identity();
  seabed.translation() = Eigen::Vector3d(0, 0, 10);
  seabed.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();  // +z up
  add(scanner::sim::MakeRectangle(1.2, 1.2), seabed);
  Eigen::Isometry3d box = Eigen::Isometry3d::Identity();
  box.translation() = Eigen::Vector3d(-0.3, 0.25, 9.95);
  box.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  add(scanner::sim::MakeBox({0.2, 0.12, 0.1}), box);
  Eigen::Isometry3d sphere = Eigen::Isometry3d::Identity();
  sphere.translation() = Eigen::Vector3d(0.25, -0.3, 9.97);
  add(scanner::sim::MakeUvSphere(0.08), sphere);
  return out;
}

// Points on the structure's upper surfaces, as a scanner above it sees them, with range noise.
using Edit = std::function<Eigen::Vector3d(const Eigen::Vector3d&)>;
Survey Scan(std::uint64_t seed, const Edit& edit = {}, double noise_m = 3e-4) {
  const scanner::SurfaceSamples s = scanner::SampleSurface(Structure(), 250000, seed);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_m);
  std::vector<Eigen::Vector3d> points;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    if (s.normals[i].z() > 0.2 || s.points[i].z() > 10.0001) continue;  // faces turned down: unseen
    const Eigen::Vector3d p = s.points[i] + noise(rng) * s.normals[i];
    points.push_back(edit ? edit(p) : p);
  }
  Survey survey;
  survey.name = "scan " + std::to_string(seed);
  survey.cloud = perception::MakeCloud(points);
  // The sensor passed a metre above (what a map report gives: its poses), so faces of a design
  // model turned away from it count as unseen.
  for (const double x : {-0.4, 0.0, 0.4}) {
    for (const double y : {-0.4, 0.0, 0.4}) {
      Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
      pose.translation() = Eigen::Vector3d(x, y, 9.0);
      survey.poses.push_back(pose);
      survey.pose_covariances.push_back(Matrix6d::Identity() * 1e-8);
    }
  }
  return survey;
}

// A file of this process's own in the temporary folder (tests run side by side), removed when
// the test is done with it.
struct TempFile {
  std::filesystem::path path;
  explicit TempFile(const std::string& name)
      : path(std::filesystem::temp_directory_path() /
             ("uwscan_" + std::to_string(::getpid()) + "_" + name)) {}
  ~TempFile() {
    std::error_code ignored;
    std::filesystem::remove(path, ignored);
  }
};

Survey Design() {
  const TempFile file("compare_design.ply");
  scanner::WriteMeshPly(Structure(), file.path);
  return ReadSurvey(file.path);
}

double ChangedShare(const SurveyComparison& c) {
  return c.areas.changed_m2 / (c.areas.changed_m2 + c.areas.unchanged_m2);
}

TEST(CompareSurveys, TwoScansOfAnUnchangedStructureShowNoSignificantRegion) {
  const SurveyComparison c = CompareSurveys(Scan(2), Scan(1), {});
  EXPECT_TRUE(c.regions.empty()) << c.regions.size() << " regions, the largest "
                                 << c.regions.front().area_m2 << " m^2";
  EXPECT_LT(ChangedShare(c), 0.08);
  EXPECT_GT(c.areas.unchanged_m2, 1.0);  // most of the 1.44 m^2 seabed and the objects' tops
}

TEST(CompareSurveys, ARigidOffsetWithinReachIsRegisteredAwayNotReported) {
  Eigen::Isometry3d offset = Eigen::Isometry3d::Identity();
  offset.linear() = Eigen::AngleAxisd(0.005, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  offset.translation() = Eigen::Vector3d(0.008, -0.005, 0.004);
  const SurveyComparison c =
      CompareSurveys(Scan(2, [&](const Eigen::Vector3d& p) { return offset * p; }), Scan(1), {});
  const Eigen::Isometry3d residual = c.alignment.T_reference_map * offset;
  EXPECT_LT((residual * Eigen::Vector3d(0, 0, 10) - Eigen::Vector3d(0, 0, 10)).norm(), 1e-3);
  EXPECT_TRUE(c.regions.empty()) << c.regions.size() << " regions";
  EXPECT_LT(ChangedShare(c), 0.08);
}

TEST(CompareSurveys, AKnownDentIsFoundWithItsDepthWithinTheLevelOfDetection) {
  const Eigen::Vector2d centre(0.3, 0.3);
  const double depth_m = 0.005, radius_m = 0.05;
  const auto dent = [&](const Eigen::Vector3d& p) {
    const bool inside = (p.head<2>() - centre).norm() < radius_m && p.z() > 9.99;
    return inside ? Eigen::Vector3d(p + Eigen::Vector3d(0, 0, depth_m)) : p;  // NED: down
  };
  for (const bool design : {false, true}) {
    const SurveyComparison c = CompareSurveys(Scan(2, dent), design ? Design() : Scan(1), {});
    const char* reference = design ? "design" : "scan";
    ASSERT_FALSE(c.regions.empty()) << reference;
    const ChangeRegion& r = c.regions.front();
    EXPECT_LT((r.centroid_W.head<2>() - centre).norm(), 0.01) << reference;
    EXPECT_LT(r.mean_deviation_m, 0.0) << reference << ": material lost";
    // Away from its rim, where the cylinders take in unchanged seabed too, the dent's depth.
    int inner = 0;
    for (std::size_t i : r.core_indices) {
      const CoreDeviation& d = c.deviations[i];
      if ((d.point_W.head<2>() - centre).norm() > radius_m - 0.02) continue;
      ++inner;
      EXPECT_NEAR(d.deviation_m, -depth_m, std::max(d.lod_m, 5e-4)) << reference;
    }
    EXPECT_GT(inner, 20) << reference;
    // The cylinders' radius (1.5 cm) widens it by about a rim.
    const double smeared = M_PI * std::pow(radius_m + 0.015, 2);
    EXPECT_NEAR(r.area_m2, smeared, 0.3 * smeared) << reference;
    double other_area = 0.0;
    for (std::size_t k = 1; k < c.regions.size(); ++k) other_area += c.regions[k].area_m2;
    EXPECT_LT(other_area, 0.01 * c.areas.unchanged_m2) << reference << ": false area";
  }
}

TEST(CompareSurveys, WhatTheMapNeverSawIsNotInspectedRatherThanMissing) {
  Survey half = Scan(2);
  std::vector<Eigen::Vector3d> kept;
  for (std::size_t i = 0; i < half.cloud.size(); ++i)
    if (half.cloud.Point(i).x() < 0.0) kept.push_back(half.cloud.Point(i));
  half.cloud = perception::MakeCloud(kept);
  const SurveyComparison c = CompareSurveys(half, Scan(1), {});
  int east_inspected = 0, east = 0;
  for (const CoreDeviation& d : c.deviations) {
    if (d.point_W.x() < 0.05) continue;
    ++east;
    east_inspected += d.status != SurfaceStatus::kNotInspected;
  }
  EXPECT_GT(east, 1000);
  EXPECT_EQ(east_inspected, 0);
  EXPECT_NEAR(c.areas.not_inspected_m2, 0.7, 0.15);  // the eastern half of the 1.44 m^2
  EXPECT_TRUE(c.regions.empty());
}

std::string MessageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(CompareSurveys, BadInputGetsAOneLineErrorNamingWhatIsWrong) {
  Survey in_mm = Scan(1);
  in_mm.cloud.origin *= 1000.0;
  for (Eigen::Vector3f& p : in_mm.cloud.points) p *= 1000.0f;
  std::string m = MessageOf([&] { CompareSurveys(Scan(2), in_mm, {}); });
  EXPECT_NE(m.find("millimetres"), std::string::npos) << m;
  Survey far = Scan(2);
  far.cloud.origin += Eigen::Vector3d(50, 0, 0);
  m = MessageOf([&] { CompareSurveys(far, Scan(1), {}); });
  EXPECT_NE(m.find("does not overlap"), std::string::npos) << m;
  Survey empty;
  empty.name = "empty.ply";
  m = MessageOf([&] { CompareSurveys(empty, Scan(1), {}); });
  EXPECT_NE(m.find("no points"), std::string::npos) << m;
  const TempFile file("faceless.ply");
  const std::filesystem::path& faceless = file.path;
  std::ofstream(faceless) << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty "
                             "float y\nproperty float z\nelement face 0\nproperty list uchar int "
                             "vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
  m = MessageOf([&] { ReadSurvey(faceless); });
  EXPECT_NE(m.find("without faces"), std::string::npos) << m;
  for (const std::string& message : {m}) EXPECT_EQ(message.find('\n'), std::string::npos);
}

// A map report's pose graph information is read as the joint uncertainty of its poses; a report
// without it (an older version) reads as before; a damaged one names the entry.
TEST(CompareSurveys, AMapReportsPoseGraphInformationIsReadOrNamedWhereDamaged) {
  const TempFile map("report_map.xyz"), report("report.json");
  std::ofstream(map.path) << "0 0 10\n1 0 10\n0 1 10\n";
  nlohmann::json row = {0.0};
  for (int k = 0; k < 36; ++k) row.push_back(k % 7 == 0 ? 1e-4 : 0.0);
  nlohmann::json json = {{"uwscan_format", 1},
                         {"kind", "map_report"},
                         {"map", map.path.string()},
                         {"trajectories", {{"slam", {{0.0, 0, 0, 9, 0, 0, 0, 1}}}}},
                         {"pose_covariance", {row}}};
  const auto write_and_read = [&] {
    std::ofstream(report.path) << json.dump();
    return ReadSurvey(report.path);
  };
  EXPECT_EQ(write_and_read().joint_uncertainty, nullptr);
  nlohmann::json entries = nlohmann::json::array();
  for (int k = 0; k < 6; ++k) entries.push_back({k, k, 1e4});
  json["pose_graph_information"] = {{"size", 6}, {"pose_columns", {0}}, {"upper_entries", entries}};
  const Survey survey = write_and_read();
  ASSERT_NE(survey.joint_uncertainty, nullptr);
  const std::optional<Eigen::MatrixXd> covariance =
      survey.joint_uncertainty->CovarianceColumns({0});
  ASSERT_TRUE(covariance.has_value());
  EXPECT_NEAR((*covariance)(3, 3), 1e-4, 1e-15);
  json["pose_graph_information"]["upper_entries"][2] = {3, 2, 5.0};
  const std::string m = MessageOf(write_and_read);
  EXPECT_NE(m.find("pose_graph_information.upper_entries[2]"), std::string::npos) << m;
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
}

}  // namespace
}  // namespace uwscan::mapping
