#include "viewer/scene/change_report.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "mapping/change/change_report.hpp"
#include "scanner/common/json_fields.hpp"

namespace uwscan::viewer {
namespace {

namespace fs = std::filesystem;
using json_fields::Field;

CloudLayer DeviationLayer(const fs::path& ply) {
  const mapping::DeviationsFile f = mapping::ReadDeviationsPly(ply);
  CloudLayer layer;
  layer.name = ply.filename().string();
  if (f.points.empty()) return layer;
  layer.origin = f.points.front();
  for (std::size_t i = 0; i < f.points.size(); ++i) {
    layer.points.push_back((f.points[i] - layer.origin).cast<float>());
    layer.deviation_m.push_back(f.significant[i] ? f.deviation_m[i]
                                                 : std::numeric_limits<float>::quiet_NaN());
  }
  return layer;
}

Label RegionLabel(const nlohmann::json& region, const Field& field) {
  const std::vector<double> c = json_fields::Numbers(
      json_fields::Require(region, "centroid_m", field), 3, field["centroid_m"]);
  const double mean_m = json_fields::Numbers(
      nlohmann::json::array({json_fields::Require(region, "mean_deviation_m", field)}), 1,
      field["mean_deviation_m"])[0];
  const double area_m2 =
      json_fields::Numbers(nlohmann::json::array({json_fields::Require(region, "area_m2", field)}),
                           1, field["area_m2"])[0];
  char text[96];
  std::snprintf(text, sizeof text, "%d: %+.1f mm, %.0f cm2",
                json_fields::Require(region, "id", field).get<int>(), 1e3 * mean_m, 1e4 * area_m2);
  return {.position_W = Eigen::Vector3d(c[0], c[1], c[2]),
          .text = text,
          .colour = mean_m > 0.0 ? Rgb{255, 160, 140} : Rgb{150, 180, 255}};
}

}  // namespace

bool IsChangeReport(const fs::path& path) {
  return json_fields::ReportKind(path) == "change_report";
}

void AddChangeReport(const fs::path& path, Scene& scene, int max_labels) {
  const std::string name = path.string();
  const Field root{name, ""};
  const nlohmann::json report = json_fields::ParseJsonFile(path);
  json_fields::RequireFormatAndKind(report, "change_report", root);
  const nlohmann::json& deviations = json_fields::Require(report, "deviations", root);
  if (!deviations.is_string()) root["deviations"].Fail("expected the deviations PLY's path");
  fs::path ply = deviations.get<std::string>();
  if (ply.is_relative()) ply = path.parent_path() / ply;
  scene.clouds.push_back(DeviationLayer(ply));
  const nlohmann::json& regions = json_fields::Require(report, "regions", root);
  if (!regions.is_array()) root["regions"].Fail("expected an array");
  for (std::size_t i = 0; i < regions.size() && static_cast<int>(i) < max_labels; ++i)
    scene.labels.push_back(RegionLabel(regions[i], root["regions"][i]));
}

}  // namespace uwscan::viewer
