#include "viewer/scene/recognition_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "mapping/reconstruction/scan_file.hpp"
#include "perception/recognition/object_database.hpp"
#include "scanner/common/error.hpp"
#include "viewer/scene/json_fields.hpp"

namespace uwscan::viewer {
namespace {

using internal::Field;
using internal::Numbers;
using internal::Require;
using nlohmann::json;

constexpr double kRigidTolerance = 1e-6;         // |R^T R - I|, det(R) - 1
constexpr double kGraspAxisFraction = 0.25;      // of the object's diameter
constexpr double kMinGraspAxis_m = 0.02;
constexpr double kLabelOffsetFraction = 0.6;     // of the diameter, towards the sensor

Eigen::Isometry3d RigidPose(const json& value, const Field& field) {
  if (!value.is_object()) field.Fail("expected an object with a 4x4 \"matrix\"");
  const json& rows = Require(value, "matrix", field);
  if (!rows.is_array() || rows.size() != 4) field["matrix"].Fail("expected 4 rows of 4 numbers");
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r) {
    const std::vector<double> row = Numbers(rows[std::size_t(r)], 4, field["matrix"][std::size_t(r)]);
    for (int c = 0; c < 4; ++c) m(r, c) = row[std::size_t(c)];
  }
  const Eigen::Matrix3d R = m.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > kRigidTolerance ||
      std::abs(R.determinant() - 1.0) > kRigidTolerance || m.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) {
    field["matrix"].Fail("not a rigid motion");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.matrix() = m;
  return T;
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
  const std::vector<double> c = Numbers(Require(value, "centroid_m", field), 3, field["centroid_m"]);
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
  const json& grasps = Require(value, "grasps", field);
  if (!grasps.is_array()) field["grasps"].Fail("expected an array");
  for (std::size_t i = 0; i < grasps.size(); ++i) {
    o.grasps_S.emplace_back(Text(grasps[i], "name", field["grasps"][i]), RigidPose(grasps[i], field["grasps"][i]));
  }
  return o;
}

}  // namespace

bool IsRecognitionReport(const std::filesystem::path& path) {
  return internal::ReportKind(path) == "recognition_report";
}

RecognitionReport ReadRecognitionReport(const std::filesystem::path& path) {
  const std::string file = path.string();
  const json j = internal::ParseJsonFile(path);
  const Field root{file, ""};
  internal::RequireFormatAndKind(j, "recognition_report", root);
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
  const json& objects = Require(j, "objects", root);
  if (!objects.is_array()) root["objects"].Fail("expected an array");
  for (std::size_t i = 0; i < objects.size(); ++i) {
    report.objects.push_back(Object(objects[i], report.scan_points, root["objects"][i]));
  }
  return report;
}

void AddRecognitionReport(const RecognitionReport& report, const mapping::ReconstructionOptions& log_options,
                          Scene& scene) {
  // `recognize` triangulates a dive log with the scanner's default method: so must the viewer,
  // or the segments' indices would fall on other points.
  mapping::ReconstructionOptions scan_options = log_options;
  scan_options.method = std::nullopt;
  scan_options.sweep = report.scan_sweep;
  const mapping::ScanFile file = mapping::ReadScanFile(report.scan, scan_options);
  const perception::PointCloud& scan = file.cloud;
  if (file.rows_in_file != report.scan_points) {
    throw Error(report.scan.string() + ": has " + std::to_string(file.rows_in_file) +
                " points, the recognition report " + std::to_string(report.scan_points) +
                "; was it changed after `uwscan recognize`?");
  }
  // The report gives the file's rows; the cloud drops the rows that are not finite points.
  constexpr std::size_t kDropped = static_cast<std::size_t>(-1);
  std::vector<std::size_t> index_of_row(file.rows_in_file, kDropped);
  for (std::size_t i = 0; i < file.rows.size(); ++i) index_of_row[file.rows[i]] = i;
  CloudLayer scan_layer;
  scan_layer.name = report.scan.filename().string();
  scan_layer.origin = scan.origin;
  scan_layer.points = scan.points;
  scan_layer.intensity = scan.intensity;
  scan_layer.object_ids.assign(scan.size(), -1);
  for (std::size_t k = 0; k < report.objects.size(); ++k) {
    if (!report.objects[k].recognised()) continue;
    for (const std::size_t row : report.objects[k].segment) {
      if (index_of_row[row] == kDropped) {
        throw Error(report.scan.string() + ": row " + std::to_string(row) +
                    " is not a finite point, yet the recognition report puts it in a segment");
      }
      scan_layer.object_ids[index_of_row[row]] = static_cast<std::int32_t>(k);
    }
  }
  scene.clouds.push_back(std::move(scan_layer));

  const bool any_recognised = std::any_of(report.objects.begin(), report.objects.end(),
                                          [](const ReportedObject& o) { return o.recognised(); });
  if (!any_recognised) return;
  const perception::ObjectDatabase db = perception::ObjectDatabase::Load(report.database);
  for (std::size_t k = 0; k < report.objects.size(); ++k) {
    const ReportedObject& o = report.objects[k];
    if (!o.recognised()) continue;
    const auto model = std::find_if(db.objects.begin(), db.objects.end(),
                                    [&o](const perception::ObjectModel& m) { return m.id == o.id; });
    if (model == db.objects.end()) {
      throw Error(report.database.string() + ": has no object '" + o.id + "' (the recognition report names it)");
    }
    const perception::PointCloud placed = perception::Transformed(model->model, o.T_S_O);
    CloudLayer layer;
    layer.name = o.id + " model";
    layer.origin = placed.origin;
    layer.points = placed.points;
    layer.object_ids.assign(placed.size(), static_cast<std::int32_t>(k));
    scene.clouds.push_back(std::move(layer));

    const double axis_m = std::max(kMinGraspAxis_m, kGraspAxisFraction * model->diameter_m);
    for (const auto& [name, T_S_G] : o.grasps_S) scene.frames.push_back({o.id + " " + name, T_S_G, axis_m});
    char text[96];
    std::snprintf(text, sizeof(text), "%s %.2f", o.id.c_str(), o.score);
    // In front of the object, towards the sensor (the scan's -z), so the object does not hide it.
    const Eigen::Vector3d front = o.T_S_O.translation() - kLabelOffsetFraction * model->diameter_m * Eigen::Vector3d::UnitZ();
    scene.labels.push_back({front, text, CategoricalColour(static_cast<int>(k))});
  }
}

}  // namespace uwscan::viewer
