#include "mapping/change/change_report.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "scanner/common/atomic_file.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

namespace fs = std::filesystem;

template <typename T>
void Put(std::ofstream& out, T value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof value);  // little-endian host
}

void WriteRows(std::ofstream& out, const SurveyComparison& c) {
  for (std::size_t i = 0; i < c.deviations.size(); ++i) {
    const CoreDeviation& d = c.deviations[i];
    for (int k = 0; k < 3; ++k) Put(out, d.point_W[k]);
    for (int k = 0; k < 3; ++k) Put(out, static_cast<float>(d.normal_W[k]));
    Put(out, static_cast<float>(d.deviation_m));
    Put(out, static_cast<float>(d.lod_m));
    Put(out, static_cast<std::uint8_t>(d.status == SurfaceStatus::kChanged));
    Put(out, static_cast<std::uint8_t>(d.status != SurfaceStatus::kNotInspected));
    Put(out, static_cast<std::int32_t>(c.region_of[i]));
  }
}

nlohmann::json Vector(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json Transform(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  const Eigen::Vector3d& t = T.translation();
  return {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
}

nlohmann::json RegionJson(const ChangeRegion& r) {
  return {{"id", r.id},
          {"kind", r.mean_deviation_m > 0.0 ? "gained" : "lost"},
          {"centroid_m", Vector(r.centroid_W)},
          {"extent_m", Vector(r.extent_m)},
          {"area_m2", r.area_m2},
          {"core_points", r.core_indices.size()},
          {"mean_deviation_m", r.mean_deviation_m},
          {"extreme_deviation_m", r.extreme_deviation_m},
          {"volume_m3", r.volume_m3},
          {"significance", r.significance}};
}

constexpr const char* kProperties =
    "property double x\nproperty double y\nproperty double z\nproperty float nx\n"
    "property float ny\nproperty float nz\nproperty float deviation_m\nproperty float "
    "lod_m\nproperty uchar significant\nproperty uchar inspected\nproperty int region\n"
    "end_header\n";
constexpr std::size_t kRowBytes = 3 * 8 + 5 * 4 + 2 + 4;

template <typename T>
T Take(const char*& at) {
  T value;
  std::memcpy(&value, at, sizeof value);
  at += sizeof value;
  return value;
}

}  // namespace

DeviationsFile ReadDeviationsPly(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot read");
  std::string line, header;
  long long count = -1;
  for (int lines = 0; lines < 20 && std::getline(in, line); ++lines) {
    if (line.rfind("element vertex ", 0) == 0) count = std::atoll(line.c_str() + 15);
    if (line.rfind("property", 0) == 0 || line == "end_header") header += line + "\n";
    if (line == "end_header") break;
  }
  if (header != kProperties || count < 0) {
    throw Error(path.string() +
                ": not the deviations PLY `uwscan compare -o` writes (its properties differ)");
  }
  const std::string rows((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (rows.size() / kRowBytes < static_cast<std::size_t>(count))  // no overflow for any count
    throw Error(path.string() + ": cut short (" + std::to_string(count) + " points declared)");
  DeviationsFile f;
  const char* at = rows.data();
  for (long long i = 0; i < count; ++i) {
    Eigen::Vector3d p;
    for (int k = 0; k < 3; ++k) p[k] = Take<double>(at);
    at += 3 * sizeof(float);  // the normal
    f.points.push_back(p);
    f.deviation_m.push_back(Take<float>(at));
    f.lod_m.push_back(Take<float>(at));
    f.significant.push_back(Take<std::uint8_t>(at));
    f.inspected.push_back(Take<std::uint8_t>(at));
    f.region.push_back(Take<std::int32_t>(at));
  }
  return f;
}

void WriteDeviationsPly(const fs::path& path, const SurveyComparison& c) {
  const fs::path temporary = TemporaryBeside(path);
  {
    std::ofstream out(temporary, std::ios::binary);
    out << "ply\nformat binary_little_endian 1.0\ncomment uwscan compare: deviations along the "
           "reference's normals, metres\nelement vertex "
        << c.deviations.size() << "\n"
        << kProperties;
    WriteRows(out, c);
    out.flush();
    if (!out) {
      const std::string reason = errno != 0 ? std::string(" (") + std::strerror(errno) + ")" : "";
      out.close();
      std::error_code ignored;
      fs::remove(temporary, ignored);
      throw Error(path.string() + ": cannot write" + reason);
    }
  }
  ReplaceWithTemporary(temporary, path);
}

nlohmann::json ChangeReportJson(const SurveyComparison& c, const Survey& map,
                                const Survey& reference, const CompareOptions& options,
                                const std::string& deviations_ply) {
  const auto absolute = [](const std::string& path) {
    return path.empty() ? std::string() : fs::absolute(path).lexically_normal().string();
  };
  nlohmann::json report = {{"uwscan_format", 1}, {"kind", "change_report"}};
  report["map"] = {{"file", absolute(map.name)}, {"kind", ToString(map.kind)}};
  report["reference"] = {{"file", absolute(reference.name)}, {"kind", ToString(reference.kind)}};
  report["deviations"] = absolute(deviations_ply);
  const SurveyAlignment& a = c.alignment;
  int tiles_registered = 0;
  for (const SurveyAlignment::Tile& t : a.tiles) tiles_registered += t.registered ? 1 : 0;
  report["alignment"] = {{"T_reference_map", Transform(a.T_reference_map)},
                         {"registered", a.registered},
                         {"fitness", a.global_fitness},
                         {"rmse_m", a.global_rmse_m},
                         {"tile_m", a.tile_m},
                         {"tiles", a.tiles.size()},
                         {"tiles_registered", tiles_registered}};
  const DeviationOptions& d = options.deviation;
  report["settings"] = {{"confidence", d.confidence},
                        {"core_spacing_m", d.core_spacing_m},
                        {"normal_radius_m", d.normal_radius_m},
                        {"cylinder_radius_m", d.cylinder_radius_m},
                        {"max_depth_m", d.max_depth_m},
                        {"map_point_sigma_m", d.map_point_sigma_m},
                        {"reference_point_sigma_m",
                         reference.kind == SurveyKind::kDesign ? 0.0 : d.reference_point_sigma_m},
                        {"pose_covariances_used", c.pose_covariances_used},
                        {"joint_pose_uncertainty_used", c.joint_pose_uncertainty_used},
                        {"seen_within_m", options.seen_within_m}};
  report["surface"] = {{"core_points", c.areas.core_points},
                       {"unchanged_m2", c.areas.unchanged_m2},
                       {"changed_m2", c.areas.changed_m2},
                       {"not_inspected_m2", c.areas.not_inspected_m2}};
  nlohmann::json regions = nlohmann::json::array();
  for (const ChangeRegion& r : c.regions) regions.push_back(RegionJson(r));
  report["regions"] = regions;
  report["seconds"] = c.seconds;
  return report;
}

std::string ChangeReportMarkdown(const SurveyComparison& c, const Survey& map,
                                 const Survey& reference) {
  std::string text = "# What the inspection found\n\n";
  char line[512];
  std::snprintf(line, sizeof line,
                "Map `%s` against %s `%s`: %.3f m^2 unchanged, %.3f m^2 changed, %.3f m^2 not "
                "inspected.\n\n",
                map.name.c_str(), ToString(reference.kind), reference.name.c_str(),
                c.areas.unchanged_m2, c.areas.changed_m2, c.areas.not_inspected_m2);
  text += line;
  text +=
      "| region | kind | centroid (m) | extent (mm) | area (cm^2) | mean (mm) | extreme (mm) | "
      "volume (cm^3) | significance |\n|---:|---|---|---|---:|---:|---:|---:|---:|\n";
  for (const ChangeRegion& r : c.regions) {
    std::snprintf(
        line, sizeof line,
        "| %d | %s | %.3f %.3f %.3f | %.0f x %.0f x %.0f | %.1f | %+.1f | %+.1f | %+.1f | "
        "%.1f |\n",
        r.id, r.mean_deviation_m > 0.0 ? "gained" : "lost", r.centroid_W.x(), r.centroid_W.y(),
        r.centroid_W.z(), 1e3 * r.extent_m.x(), 1e3 * r.extent_m.y(), 1e3 * r.extent_m.z(),
        1e4 * r.area_m2, 1e3 * r.mean_deviation_m, 1e3 * r.extreme_deviation_m, 1e6 * r.volume_m3,
        r.significance);
    text += line;
  }
  if (c.regions.empty()) text += "\nNo significant change.\n";
  return text;
}

}  // namespace uwscan::mapping
