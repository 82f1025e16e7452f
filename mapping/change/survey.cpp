#include "mapping/change/survey.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "perception/cloud/cloud_io.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"
#include "scanner/common/json_fields.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/common/ply_reader.hpp"
#include "scanner/common/triangle_mesh.hpp"

namespace uwscan::mapping {
namespace {

namespace fs = std::filesystem;
using json_fields::Field;

constexpr double kMaxDesignSamples = 50e6;

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

Eigen::Isometry3d TumPose(const std::vector<double>& row) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(row[1], row[2], row[3]);
  T.linear() = Eigen::Quaterniond(row[7], row[4], row[5], row[6]).normalized().toRotationMatrix();
  return T;
}

// The report lists covariances as (x, y, z, roll, pitch, yaw); the graph's order is
// [rotation, position].
Matrix6d GraphOrder(const std::vector<double>& row) {
  Matrix6d c;
  for (int r = 0; r < 6; ++r) {
    for (int k = 0; k < 6; ++k) c(r, k) = row[1 + 6 * r + k];
  }
  Matrix6d ordered;
  ordered << c.bottomRightCorner<3, 3>(), c.bottomLeftCorner<3, 3>(), c.topRightCorner<3, 3>(),
      c.topLeftCorner<3, 3>();
  return ordered;
}

// The pose graph's information a report of this version carries (InformationJson in the map
// command); null for an older report.
std::shared_ptr<const JointPoseUncertainty> ReadJointUncertainty(const nlohmann::json& report,
                                                                 const Field& root) {
  if (!report.contains("pose_graph_information")) return nullptr;
  const Field field = root["pose_graph_information"];
  const nlohmann::json& block = report["pose_graph_information"];
  const nlohmann::json& size = json_fields::Require(block, "size", field);
  const nlohmann::json& columns = json_fields::Require(block, "pose_columns", field);
  const nlohmann::json& entries = json_fields::Require(block, "upper_entries", field);
  if (!size.is_number_integer() || size.get<long long>() < 0 || size.get<long long>() > 1e8)
    field["size"].Fail("expected the information's number of rows");
  const auto n = static_cast<Eigen::Index>(size.get<long long>());
  if (!columns.is_array() || !entries.is_array())
    field.Fail("expected pose_columns and upper_entries arrays");
  std::vector<int> pose_columns;
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (!columns[i].is_number_integer()) field["pose_columns"][i].Fail("expected a column");
    pose_columns.push_back(columns[i].get<int>());
  }
  std::vector<Eigen::Triplet<double>> triplets;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const std::vector<double> e = json_fields::Numbers(entries[i], 3, field["upper_entries"][i]);
    const auto r = static_cast<Eigen::Index>(e[0]), c = static_cast<Eigen::Index>(e[1]);
    if (r != e[0] || c != e[1] || r < 0 || c < r || c >= n)
      field["upper_entries"][i].Fail("expected [row, column, value] with row <= column < size");
    triplets.emplace_back(r, c, e[2]);
    if (r != c) triplets.emplace_back(c, r, e[2]);
  }
  Eigen::SparseMatrix<double> information(n, n);
  information.setFromTriplets(triplets.begin(), triplets.end());
  try {
    return std::make_shared<const JointPoseUncertainty>(std::move(information),
                                                        std::move(pose_columns));
  } catch (const Error& e) {
    field.Fail(e.what());
  }
}

Survey ReadMapReport(const fs::path& path, const SurveyReadOptions& options) {
  const std::string name = path.string();
  const Field root{name, ""};
  const nlohmann::json report = json_fields::ParseJsonFile(path);
  json_fields::RequireFormatAndKind(report, "map_report", root);
  Survey survey;
  survey.name = name;
  survey.kind = SurveyKind::kMap;
  const nlohmann::json& map = json_fields::Require(report, "map", root);
  if (!map.is_string()) root["map"].Fail("expected the map file's path");
  fs::path map_path = map.get<std::string>();
  if (map_path.is_relative()) map_path = path.parent_path() / map_path;
  survey.cloud = perception::ReadCloud(map_path);
  const Field slam_field = root["trajectories"]["slam"];
  const nlohmann::json& slam = json_fields::Require(
      json_fields::Require(report, "trajectories", root), "slam", root["trajectories"]);
  const nlohmann::json& covariance = json_fields::Require(report, "pose_covariance", root);
  if (!slam.is_array() || !covariance.is_array() || covariance.size() != slam.size() ||
      slam.empty()) {
    root["pose_covariance"].Fail("expected one covariance per SLAM pose (map with --json)");
  }
  for (std::size_t i = 0; i < slam.size(); ++i) {
    survey.poses.push_back(TumPose(json_fields::Numbers(slam[i], 8, slam_field[i])));
    survey.pose_covariances.push_back(
        GraphOrder(json_fields::Numbers(covariance[i], 37, root["pose_covariance"][i])));
  }
  if (options.units_to_m != 1.0) root.Fail("a map report is in metres (no --units)");
  survey.joint_uncertainty = ReadJointUncertainty(report, root);
  if (survey.joint_uncertainty && survey.joint_uncertainty->pose_count() != survey.poses.size())
    root["pose_graph_information"]["pose_columns"].Fail("expected one per SLAM pose");
  return survey;
}

Survey ReadDesign(const fs::path& path, const SurveyReadOptions& options) {
  scanner::TriangleMesh mesh = scanner::LoadMesh(path);
  for (Eigen::Vector3d& v : mesh.vertices) v *= options.units_to_m;
  double area_m2 = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[static_cast<std::size_t>(t[0])];
    area_m2 += 0.5 * (mesh.vertices[static_cast<std::size_t>(t[1])] - a)
                         .cross(mesh.vertices[static_cast<std::size_t>(t[2])] - a)
                         .norm();
  }
  const double count = std::ceil(area_m2 / (options.design_spacing_m * options.design_spacing_m));
  if (!(count <= kMaxDesignSamples)) {
    throw Error(path.string() + ": " + std::to_string(area_m2) + " m^2 of surface at " +
                std::to_string(options.design_spacing_m) +
                " m spacing is more than 50 million samples (wrong units? a coarser spacing?)");
  }
  const scanner::SurfaceSamples samples =
      scanner::SampleSurface(mesh, static_cast<int>(count), options.seed);
  Survey survey;
  survey.name = path.string();
  survey.kind = SurveyKind::kDesign;
  survey.cloud = perception::MakeCloud(samples.points);
  for (const Eigen::Vector3d& n : samples.normals) survey.cloud.normals.push_back(n.cast<float>());
  return survey;
}

Survey ReadCloudSurvey(const fs::path& path, const SurveyReadOptions& options) {
  Survey survey;
  survey.name = path.string();
  survey.kind = SurveyKind::kCloud;
  survey.cloud = perception::ReadCloud(path);
  survey.cloud.origin *= options.units_to_m;
  for (Eigen::Vector3f& p : survey.cloud.points) p *= static_cast<float>(options.units_to_m);
  return survey;
}

}  // namespace

const char* ToString(SurveyKind kind) {
  switch (kind) {
    case SurveyKind::kDesign:
      return "design";
    case SurveyKind::kCloud:
      return "cloud";
    case SurveyKind::kMap:
      return "map";
  }
  return "?";
}

void SurveyReadOptions::Check() const {
  const OptionChecks check("SurveyReadOptions");
  check.Positive("units_to_m", units_to_m);
  check.Positive("design_spacing_m", design_spacing_m, "m");
}

Survey ReadSurvey(const fs::path& path, const SurveyReadOptions& options) {
  options.Check();
  RequireRegularFile(path, path.string());
  const std::string extension = Lower(path.extension().string());
  if (extension == ".json") return ReadMapReport(path, options);
  if (extension == ".obj" || extension == ".stl" || extension == ".off")
    return ReadDesign(path, options);
  if (extension == ".ply") {
    const std::optional<long long> faces = scanner::PlyFaceCount(path);
    if (faces && *faces <= 0) {
      throw Error(path.string() +
                  ": a mesh without faces (its face element is empty); give a cloud without a "
                  "face element, or a mesh with triangles");
    }
    if (faces) return ReadDesign(path, options);
  }
  return ReadCloudSurvey(path, options);
}

Survey SurveyOfDive(const DiveMapping& mapping, const std::string& name) {
  if (mapping.covariances.size() != mapping.slam.size() || mapping.slam.empty())
    throw Error(name + ": the dive's mapping has no pose covariances");
  Survey survey;
  survey.name = name;
  survey.kind = SurveyKind::kMap;
  survey.cloud = mapping.map;
  for (std::size_t i = 0; i < mapping.slam.size(); ++i) {
    survey.poses.push_back(mapping.slam[i].T_W_V);
    survey.pose_covariances.push_back(mapping.covariances[i]);
  }
  survey.joint_uncertainty = mapping.joint_uncertainty;
  return survey;
}

double PoseSigmaAlongNormal(const Survey& survey, const Eigen::Vector3d& p_W,
                            const Eigen::Vector3d& normal_W) {
  if (survey.poses.empty()) return 0.0;
  std::size_t nearest = 0;
  double nearest_m2 = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < survey.poses.size(); ++i) {
    const double d2 = (survey.poses[i].translation() - p_W).squaredNorm();
    if (d2 < nearest_m2) {
      nearest_m2 = d2;
      nearest = i;
    }
  }
  // A small rotation w about the pose's position t and a shift v move p by w x (p - t) + v.
  const Eigen::Vector3d lever = p_W - survey.poses[nearest].translation();
  Eigen::Matrix<double, 1, 6> j;
  j << lever.cross(normal_W).transpose(), normal_W.transpose();
  const double variance = j * survey.pose_covariances[nearest] * j.transpose();
  return std::sqrt(std::max(variance, 0.0));
}

}  // namespace uwscan::mapping
