#include "perception/recognition/recognition_report.hpp"

#include <cmath>
#include <cstdint>

#include "scanner/common/json_fields.hpp"

namespace uwscan::perception {
namespace {

using json_fields::Field;
using json_fields::Numbers;
using json_fields::Require;
using nlohmann::json;

constexpr double kRigidTolerance = 1e-6;  // |R^T R - I|, det(R) - 1

Eigen::Isometry3d RigidPose(const json& value, const Field& field) {
  if (!value.is_object()) field.Fail("expected an object with a 4x4 \"matrix\"");
  const json& rows = Require(value, "matrix", field);
  if (!rows.is_array() || rows.size() != 4) field["matrix"].Fail("expected 4 rows of 4 numbers");
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    const std::vector<double> row =
        Numbers(rows[std::size_t(r)], 4, field["matrix"][std::size_t(r)]);
    for (int c = 0; c < 4; ++c) m(r, c) = row[std::size_t(c)];
  }
  const Eigen::Matrix3d R = m.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > kRigidTolerance ||
      std::abs(R.determinant() - 1.0) > kRigidTolerance ||
      m.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) {
    field["matrix"].Fail("not a rigid motion");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.matrix() = m;
  return T;
}

Eigen::Matrix<double, 6, 6> Covariance(const json& value, const Field& field) {
  if (!value.is_array() || value.size() != 6) field.Fail("expected 6 rows of 6 numbers");
  Eigen::Matrix<double, 6, 6> c;
  for (int r = 0; r < 6; ++r) {
    const std::vector<double> row = Numbers(value[std::size_t(r)], 6, field[std::size_t(r)]);
    for (int k = 0; k < 6; ++k) c(r, k) = row[std::size_t(k)];
  }
  return c;
}

std::string Text(const json& object, const std::string& key, const Field& field) {
  const json& value = Require(object, key, field);
  if (!value.is_string()) field[key].Fail("expected a string");
  return value.get<std::string>();
}

ReportedObject Object(const json& value, std::size_t scan_points, const Field& field) {
  if (!value.is_object()) field.Fail("expected an object");
  ReportedObject o;
  o.id = Text(value, "id", field);
  const std::vector<double> c =
      Numbers(Require(value, "centroid_m", field), 3, field["centroid_m"]);
  o.centroid_S = Eigen::Vector3d(c[0], c[1], c[2]);
  const json& segment = Require(value, "segment", field);
  if (!segment.is_array()) field["segment"].Fail("expected an array of point indices");
  o.segment.reserve(segment.size());
  for (std::size_t i = 0; i < segment.size(); ++i) {
    if (!segment[i].is_number_unsigned() || segment[i].get<std::uint64_t>() >= scan_points) {
      field["segment"][i].Fail("not an index below scan_points " + std::to_string(scan_points));
    }
    o.segment.push_back(segment[i].get<std::size_t>());
  }
  if (!o.recognised()) return o;
  const json& score = Require(value, "score", field);
  if (!score.is_number()) field["score"].Fail("not a number");
  o.score = score.get<double>();
  o.T_S_O = RigidPose(Require(value, "T_S_O", field), field["T_S_O"]);
  if (value.contains("covariance"))
    o.covariance = Covariance(value["covariance"], field["covariance"]);
  const json& grasps = Require(value, "grasps", field);
  if (!grasps.is_array()) field["grasps"].Fail("expected an array");
  for (std::size_t i = 0; i < grasps.size(); ++i) {
    o.grasps_S.emplace_back(Text(grasps[i], "name", field["grasps"][i]),
                            RigidPose(grasps[i], field["grasps"][i]));
  }
  return o;
}

}  // namespace

bool IsRecognitionReport(const std::filesystem::path& path) {
  return json_fields::ReportKind(path) == "recognition_report";
}

RecognitionReport ReadRecognitionReport(const std::filesystem::path& path) {
  const std::string file = path.string();
  const json j = json_fields::ParseJsonFile(path);
  const Field root{file, ""};
  json_fields::RequireFormatAndKind(j, "recognition_report", root);
  RecognitionReport report;
  report.scan = path.parent_path() / Text(j, "scan", root);
  report.database = path.parent_path() / Text(j, "database", root);
  const json& scan_points = Require(j, "scan_points", root);
  if (!scan_points.is_number_unsigned()) root["scan_points"].Fail("expected a point count");
  report.scan_points = scan_points.get<std::size_t>();
  if (j.contains("scan_sweep")) {
    const json& sweep = j["scan_sweep"];
    if (!sweep.is_number_integer()) root["scan_sweep"].Fail("expected a sweep number");
    report.scan_sweep = sweep.get<int>();
  }
  if (j.contains("scan_frame")) {
    const json& frame = j["scan_frame"];
    const Field field = root["scan_frame"];
    if (!frame.is_object()) field.Fail("expected an object");
    const json& unit = Require(frame, "metres_per_unit", field);
    if (!unit.is_number() || !(unit.get<double>() > 0.0) || !std::isfinite(unit.get<double>())) {
      field["metres_per_unit"].Fail("expected a finite number > 0");
    }
    report.scan_metres_per_unit = unit.get<double>();
    report.scan_T_file_sensor =
        RigidPose(Require(frame, "T_file_sensor", field), field["T_file_sensor"]);
  }
  const json& objects = Require(j, "objects", root);
  if (!objects.is_array()) root["objects"].Fail("expected an array");
  for (std::size_t i = 0; i < objects.size(); ++i) {
    report.objects.push_back(Object(objects[i], report.scan_points, root["objects"][i]));
  }
  return report;
}

}  // namespace uwscan::perception
