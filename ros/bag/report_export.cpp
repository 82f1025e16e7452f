#include "ros/bag/report_export.hpp"

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "perception/cloud/cloud_io.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

struct TimedPose {
  double time_s = 0.0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
};

nlohmann::json ReadReport(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw Error(path.string() + ": cannot open the report");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error(path.string() + ": not JSON (" + e.what() + ")");
  }
}

// Rows [t, tx, ty, tz, qx, qy, qz, qw] of trajectories[name].
std::vector<TimedPose> Trajectory(const nlohmann::json& report, const std::string& name,
                                  const std::filesystem::path& path) {
  std::vector<TimedPose> poses;
  const nlohmann::json& rows = report.at("trajectories").at(name);
  for (const nlohmann::json& row : rows) {
    if (!row.is_array() || row.size() != 8) {
      throw Error(path.string() + ": trajectories." + name +
                  ": a row is not [t, tx, ty, tz, qx, qy, qz, qw]");
    }
    TimedPose p;
    p.time_s = row[0].get<double>();
    const Eigen::Quaterniond q(row[7].get<double>(), row[4].get<double>(), row[5].get<double>(),
                               row[6].get<double>());
    p.T.linear() = q.normalized().toRotationMatrix();
    p.T.translation() =
        Eigen::Vector3d(row[1].get<double>(), row[2].get<double>(), row[3].get<double>());
    poses.push_back(p);
  }
  return poses;
}

// pose_covariance rows [t, 36 values (x, y, z, roll, pitch, yaw)] by time: ROS's order already.
std::map<double, Covariance6d> Covariances(const nlohmann::json& report) {
  std::map<double, Covariance6d> covariances;
  if (!report.contains("pose_covariance")) return covariances;
  for (const nlohmann::json& row : report.at("pose_covariance")) {
    Covariance6d c;
    for (int i = 0; i < 36; ++i)
      c(i / 6, i % 6) = row.at(static_cast<std::size_t>(i + 1)).get<double>();
    covariances[row.at(0).get<double>()] = c;
  }
  return covariances;
}

PathMessage PathUpTo(const std::vector<TimedPose>& poses, std::size_t last, double origin_s,
                     const std::string& frame) {
  PathMessage path;
  path.header = {origin_s + poses[last].time_s, frame};
  for (std::size_t i = 0; i <= last; ++i) {
    path.stamps_s.push_back(origin_s + poses[i].time_s);
    path.poses.push_back(poses[i].T);
  }
  return path;
}

CloudMessage MapCloud(const nlohmann::json& report, const std::filesystem::path& path,
                      const Header& header) {
  std::filesystem::path map = report.at("map").get<std::string>();
  if (map.is_relative()) map = path.parent_path() / map;
  const perception::PointCloud cloud = perception::ReadCloud(map);
  CloudMessage message;
  message.header = header;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    message.points.push_back(cloud.Point(i).cast<float>());
  return message;
}

struct Trajectories {
  std::vector<TimedPose> slam, navigation, truth;
};

Trajectories ReadTrajectories(const nlohmann::json& report, const std::filesystem::path& path) {
  Trajectories t;
  t.slam = Trajectory(report, "slam", path);
  t.navigation = Trajectory(report, "dead_reckoning", path);
  if (report.at("trajectories").contains("truth")) t.truth = Trajectory(report, "truth", path);
  if (t.slam.empty()) throw Error(path.string() + ": trajectories.slam is empty");
  if (t.navigation.size() != t.slam.size() ||
      (!t.truth.empty() && t.truth.size() != t.slam.size())) {
    throw Error(path.string() + ": the trajectories do not have one pose per anchor each");
  }
  return t;
}

void WriteAnchor(const Trajectories& t, std::size_t i, double origin_s,
                 const std::map<double, Covariance6d>& covariances, const BagExportOptions& o,
                 BagWriter& bag) {
  const RosFrames& f = o.frames;
  const RosTopics& topics = o.topics;
  const double stamp_s = origin_s + t.slam[i].time_s;
  bag.Write(topics.slam_path, PathUpTo(t.slam, i, origin_s, f.map));
  bag.Write(topics.navigation_path, PathUpTo(t.navigation, i, origin_s, f.map));
  if (!t.truth.empty()) bag.Write(topics.truth_path, PathUpTo(t.truth, i, origin_s, f.map));
  if (const auto c = covariances.find(t.slam[i].time_s); c != covariances.end()) {
    bag.Write(topics.pose, PoseMessage{{stamp_s, f.map}, t.slam[i].T, c->second});
  }
  const Eigen::Isometry3d T_map_odom = t.slam[i].T * t.navigation[i].T.inverse();
  bag.Write(topics.tf, std::vector<TransformMessage>{{{stamp_s, f.map}, f.odom, T_map_odom}},
            stamp_s);
}

}  // namespace

ReportExportSummary ExportMapReport(const std::filesystem::path& path, double origin_s,
                                    const BagExportOptions& o, BagWriter& bag) {
  const nlohmann::json report = ReadReport(path);
  if (report.value("kind", "") != "map_report")
    throw Error(path.string() + ": not a map report (kind map_report)");
  ReportExportSummary summary;
  try {
    const Trajectories t = ReadTrajectories(report, path);
    const std::map<double, Covariance6d> covariances = Covariances(report);
    const CloudMessage map =
        MapCloud(report, path, {origin_s + t.slam.front().time_s, o.frames.map});
    bag.Write(o.topics.map, map);
    for (std::size_t i = 0; i < t.slam.size(); ++i)
      WriteAnchor(t, i, origin_s, covariances, o, bag);
    summary.anchors = static_cast<std::int64_t>(t.slam.size());
    summary.map_points = static_cast<std::int64_t>(map.points.size());
    summary.truth = !t.truth.empty();
  } catch (const nlohmann::json::exception& e) {
    throw Error(path.string() + ": a field is missing or of the wrong type (" + e.what() + ")");
  }
  return summary;
}

}  // namespace uwscan::ros
