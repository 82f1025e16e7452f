#include "apps/perception/recognition_json.hpp"

#include <cmath>

namespace uwscan::app {
namespace {

nlohmann::json Matrix(const Eigen::Matrix4d& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2), m(r, 3)});
  return rows;
}

nlohmann::json Vector(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

nlohmann::json Pose(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  return {{"matrix", Matrix(T.matrix())},
          {"position_m", Vector(T.translation())},
          {"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}}};
}

// A pose in the scan file's frame and units (the rows of "matrix" and "position" in them).
nlohmann::json PoseInFile(const Eigen::Isometry3d& T_file_X) {
  const Eigen::Quaterniond q(T_file_X.linear());
  return {{"matrix", Matrix(T_file_X.matrix())},
          {"position", Vector(T_file_X.translation())},
          {"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}}};
}

// T_S_X (metres) as a pose in the scan file's frame and units.
Eigen::Isometry3d InFile(const Eigen::Isometry3d& T_S_X, const mapping::ScanFile& scan) {
  Eigen::Isometry3d T_S_X_units = T_S_X;
  T_S_X_units.translation() /= scan.metres_per_unit;
  return scan.T_file_sensor * T_S_X_units;
}

nlohmann::json ObjectJson(const perception::RecognizedObject& o, const mapping::ScanFile& scan) {
  const std::vector<std::size_t>& rows = scan.rows;
  std::vector<std::size_t> segment_rows;
  segment_rows.reserve(o.segment.size());
  for (std::size_t i : o.segment) segment_rows.push_back(rows.at(i));
  nlohmann::json j = {{"id", o.object_id},
                      {"points", o.segment.size()},
                      {"segment", segment_rows},
                      {"centroid_m", Vector(o.centroid_S)}};
  nlohmann::json candidates = nlohmann::json::array();
  for (const perception::RecognitionCandidate& c : o.candidates) {
    candidates.push_back(
        {{"id", c.object_id},
         {"chi_square", c.chi_square},
         {"view", c.view},
         {"fitness", c.fitness},
         {"close", c.close},
         {"missing", c.missing},
         {"buried", c.buried},
         {"clearance_m",
          std::isfinite(c.clearance_m) ? nlohmann::json(c.clearance_m) : nlohmann::json()},
         {"rmse_m", c.rmse_m},
         {"score", c.score},
         {"verified", c.verified}});
  }
  j["candidates"] = candidates;
  if (o.object_id == "unknown") return j;
  j["score"] = o.score;
  j["chi_square"] = o.chi_square;
  j["margin"] = o.margin;
  j["T_S_O"] = Pose(o.T_S_O);
  j["T_file_O"] = PoseInFile(InFile(o.T_S_O, scan));
  nlohmann::json covariance = nlohmann::json::array();
  nlohmann::json std_dev = nlohmann::json::array();
  for (int r = 0; r < 6; ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (int c = 0; c < 6; ++c) row.push_back(o.covariance(r, c));
    covariance.push_back(row);
    std_dev.push_back(std::sqrt(std::max(0.0, o.covariance(r, r))));
  }
  j["covariance"] = covariance;
  j["std_rot_rad_trans_m"] = std_dev;
  nlohmann::json free = nlohmann::json::array();
  for (const perception::FreeDirection& f : o.free_directions) {
    free.push_back({{"kind", perception::ToString(f.kind)},
                    {"motion", perception::ToString(f.motion)},
                    {"axis", Vector(f.axis_S)},
                    {"point_m", Vector(f.point_S)},
                    {"order", f.order}});
  }
  j["free_directions"] = free;
  nlohmann::json equivalent = nlohmann::json::array();
  for (const Eigen::Isometry3d& T_S_O : o.equivalent_poses_S) equivalent.push_back(Pose(T_S_O));
  j["equivalent_poses"] = equivalent;
  nlohmann::json equivalent_objects = nlohmann::json::array();
  for (const auto& [id, T_S_O] : o.equivalent_objects_S) {
    nlohmann::json e = Pose(T_S_O);
    e["id"] = id;
    equivalent_objects.push_back(e);
  }
  j["equivalent_objects"] = equivalent_objects;
  nlohmann::json grasps = nlohmann::json::array();
  for (const auto& [name, T_S_G] : o.grasps_S) {
    nlohmann::json g = Pose(T_S_G);
    g["name"] = name;
    g["approach"] = Vector(T_S_G.linear().col(2));
    grasps.push_back(g);
  }
  j["grasps"] = grasps;
  return j;
}

}  // namespace

nlohmann::json RecognitionJson(const perception::RecognitionResult& result,
                               const mapping::ScanFile& scan) {
  nlohmann::json objects = nlohmann::json::array();
  for (const perception::RecognizedObject& o : result.objects)
    objects.push_back(ObjectJson(o, scan));
  return {{"uwscan_format", 1},
          {"kind", "recognition_report"},
          {"scan_points", scan.rows_in_file},
          {"scan_frame",
           {{"metres_per_unit", scan.metres_per_unit},
            {"viewpoint", mapping::ToString(scan.viewpoint)},
            {"T_file_sensor", PoseInFile(scan.T_file_sensor)}}},
          {"objects", objects},
          {"plane_points", result.plane_points},
          {"stage_seconds", result.stage_seconds}};
}

}  // namespace uwscan::app
