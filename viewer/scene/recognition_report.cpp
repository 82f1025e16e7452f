#include "viewer/scene/recognition_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "mapping/reconstruction/scan_file.hpp"
#include "perception/recognition/object_database.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/json_fields.hpp"

namespace uwscan::viewer {
namespace {

constexpr double kGraspAxisFraction = 0.25;  // of the object's diameter
constexpr double kMinGraspAxis_m = 0.02;
constexpr double kLabelOffsetFraction = 0.6;  // of the diameter, towards the sensor

}  // namespace

void AddRecognitionReport(const RecognitionReport& report,
                          const mapping::ReconstructionOptions& log_options, Scene& scene) {
  // `recognize` triangulates a dive log with the scanner's default method: so must the viewer,
  // or the segments' indices would fall on other points.
  mapping::ReconstructionOptions scan_options = log_options;
  scan_options.method = std::nullopt;
  scan_options.sweep = report.scan_sweep;
  const mapping::ScanFile file =
      mapping::ReadScanFile(report.scan, scan_options, mapping::ReportedScanFrame(report));
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
    const auto model =
        std::find_if(db.objects.begin(), db.objects.end(),
                     [&o](const perception::ObjectModel& m) { return m.id == o.id; });
    if (model == db.objects.end()) {
      throw Error(report.database.string() + ": has no object '" + o.id +
                  "' (the recognition report names it)");
    }
    const perception::PointCloud placed = perception::Transformed(model->model, o.T_S_O);
    CloudLayer layer;
    layer.name = o.id + " model";
    layer.origin = placed.origin;
    layer.points = placed.points;
    layer.object_ids.assign(placed.size(), static_cast<std::int32_t>(k));
    scene.clouds.push_back(std::move(layer));

    const double axis_m = std::max(kMinGraspAxis_m, kGraspAxisFraction * model->diameter_m);
    for (const auto& [name, T_S_G] : o.grasps_S)
      scene.frames.push_back({o.id + " " + name, T_S_G, axis_m});
    char text[96];
    std::snprintf(text, sizeof(text), "%s %.2f", o.id.c_str(), o.score);
    // In front of the object, towards the sensor (the scan's -z), so the object does not hide it.
    const Eigen::Vector3d front =
        o.T_S_O.translation() - kLabelOffsetFraction * model->diameter_m * Eigen::Vector3d::UnitZ();
    scene.labels.push_back({front, text, CategoricalColour(static_cast<int>(k))});
  }
}

}  // namespace uwscan::viewer
