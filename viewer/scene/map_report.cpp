#include "viewer/scene/map_report.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "perception/cloud/cloud_io.hpp"
#include "scanner/common/json_fields.hpp"
#include "scanner/common/option_checks.hpp"
#include "viewer/scene/scene_files.hpp"

namespace uwscan::viewer {
namespace {

using nlohmann::json;

using json_fields::Field;
using json_fields::Numbers;
using json_fields::Require;

std::vector<StampedPose> Trajectory(const json& value, const Field& field) {
  if (!value.is_array()) field.Fail("expected an array of [t tx ty tz qx qy qz qw]");
  std::vector<StampedPose> poses;
  for (std::size_t i = 0; i < value.size(); ++i) {
    const std::vector<double> v = Numbers(value[i], 8, field[i]);
    poses.push_back(PoseFromTum(v, field.file + ": " + field[i].path));
  }
  return poses;
}

PoseCovariance Covariance(const json& value, const Field& field) {
  const std::vector<double> v = Numbers(value, 37, field);
  PoseCovariance c;
  c.time_s = v[0];
  for (int r = 0; r < 6; ++r) {
    for (int k = 0; k < 6; ++k) c.covariance(r, k) = v[1 + 6 * r + k];
  }
  return c;
}

LoopClosure Loop(const json& value, const Field& field) {
  if (!value.is_object()) field.Fail("expected an object");
  LoopClosure loop;
  const json& from = Require(value, "from_submap", field);
  const json& to = Require(value, "to_submap", field);
  const json& accepted = Require(value, "accepted", field);
  if (!from.is_number_integer()) field["from_submap"].Fail("not an integer");
  if (!to.is_number_integer()) field["to_submap"].Fail("not an integer");
  if (!accepted.is_boolean()) field["accepted"].Fail("not true or false");
  loop.from_submap = from.get<int>();
  loop.to_submap = to.get<int>();
  loop.accepted = accepted.get<bool>();
  if (const auto it = value.find("reason"); it != value.end() && it->is_string())
    loop.reason = it->get<std::string>();
  return loop;
}

Rgb TrajectoryColour(const std::string& name, int index) {
  if (name == "slam") return CategoricalColour(0);
  if (name == "dead_reckoning") return CategoricalColour(1);
  if (name == "truth") return CategoricalColour(2);
  return CategoricalColour(3 + index);
}

}  // namespace

bool IsMapReport(const std::filesystem::path& path) {
  return json_fields::ReportKind(path) == "map_report";
}

MapReport ReadMapReport(const std::filesystem::path& path) {
  const std::string file = path.string();
  const json j = json_fields::ParseJsonFile(path);
  const Field root{file, ""};
  json_fields::RequireFormatAndKind(j, "map_report", root);

  MapReport report;
  if (const auto it = j.find("log"); it != j.end() && it->is_string())
    report.log = it->get<std::string>();
  if (const auto it = j.find("map"); it != j.end() && !it->is_null()) {
    if (!it->is_string()) root["map"].Fail("expected a file name");
    report.map = path.parent_path() / it->get<std::string>();
  }
  const json& trajectories = Require(j, "trajectories", root);
  if (!trajectories.is_object()) root["trajectories"].Fail("expected an object of trajectories");
  for (const auto& [name, poses] : trajectories.items()) {
    report.trajectories[name] = Trajectory(poses, root["trajectories"][name]);
  }
  if (const auto it = j.find("pose_covariance"); it != j.end()) {
    if (!it->is_array()) root["pose_covariance"].Fail("expected an array");
    for (std::size_t i = 0; i < it->size(); ++i) {
      report.pose_covariance.push_back(Covariance((*it)[i], root["pose_covariance"][i]));
    }
  }
  if (const auto it = j.find("loops"); it != j.end()) {
    if (!it->is_array()) root["loops"].Fail("expected an array");
    for (std::size_t i = 0; i < it->size(); ++i)
      report.loops.push_back(Loop((*it)[i], root["loops"][i]));
  }
  return report;
}

void MapReportDrawing::Check() const {
  const OptionChecks check("MapReportDrawing");
  check.AtLeast("ellipsoid_every", ellipsoid_every, 1);
  check.Positive("sigmas", sigmas);
}

void AddMapReport(const MapReport& report, const MapReportDrawing& drawing, Scene& scene) {
  drawing.Check();
  if (report.map) AddCloudFile(*report.map, scene);
  int other = 0;
  for (const auto& [name, poses] : report.trajectories) {
    TrajectoryLayer layer = TrajectoryFromPoses(name, poses);
    layer.colour = TrajectoryColour(
        name, name == "slam" || name == "dead_reckoning" || name == "truth" ? 0 : other++);
    scene.trajectories.push_back(std::move(layer));
  }
  const auto slam = report.trajectories.find("slam");
  if (slam == report.trajectories.end() || slam->second.empty()) return;
  const std::vector<StampedPose>& poses = slam->second;
  for (std::size_t i = 0; i < report.pose_covariance.size();
       i += static_cast<std::size_t>(drawing.ellipsoid_every)) {
    const PoseCovariance& c = report.pose_covariance[i];
    // The pose the covariance belongs to: the SLAM pose nearest its time.
    const auto nearest = std::min_element(
        poses.begin(), poses.end(), [&c](const StampedPose& a, const StampedPose& b) {
          return std::abs(a.time_s - c.time_s) < std::abs(b.time_s - c.time_s);
        });
    UncertaintyEllipsoid e;
    e.centre_W = nearest->T_W_B.translation();
    e.covariance_m2 = c.covariance.topLeftCorner<3, 3>();
    e.sigmas = drawing.sigmas;
    e.colour = TrajectoryColour("slam", 0);
    scene.ellipsoids.push_back(e);
  }
}

}  // namespace uwscan::viewer
