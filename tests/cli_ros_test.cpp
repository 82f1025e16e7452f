// `uwscan bag` and `uwscan ros inspect` end to end, as a user on a vehicle runs them: a simulated
// dive exported as a ROS bag, read back by ROS's own Python reader, imported and mapped; the bag
// played into the node under a ROS master of the test's own (tests/ros/replay_dive.sh, inside a
// private network namespace: cmake/run_in_netns.sh).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include "perception/cloud/cloud_io.hpp"
#include "tests/cli_run.hpp"

namespace {

using uwscan::test::CommandRun;
using uwscan::test::RunCommand;
using uwscan::test::RunUwscan;

std::string SourcePath(const std::string& relative) { return std::string(UWSCAN_SOURCE_DIR) + "/" + relative; }

// A folder of this test process's own, removed at exit.
const std::filesystem::path& Folder() {
  static const struct Scratch {
    std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("uwscan_cli_ros_test_" + std::to_string(::getpid()));
    Scratch() { std::filesystem::create_directories(path); }
    ~Scratch() { std::filesystem::remove_all(path); }
  } scratch;
  return scratch.path;
}

std::filesystem::path TempPath(const std::string& name) { return Folder() / name; }

// The short inspection dive (20 s, one lap with drifting navigation), simulated once.
const std::filesystem::path& ShortDive() {
  static const std::filesystem::path log = [] {
    const std::filesystem::path path = TempPath("short.db");
    const CommandRun run = RunUwscan("simulate " + SourcePath("data/scenes/inspection_short.yaml") + " -o " +
                                     path.string());
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return path;
  }();
  return log;
}

// The short dive as a bag, exported once.
const std::filesystem::path& ShortBag() {
  static const std::filesystem::path bag = [] {
    const std::filesystem::path path = TempPath("short.bag");
    const CommandRun run = RunUwscan("bag export " + ShortDive().string() + " -o " + path.string());
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return path;
  }();
  return bag;
}

struct TimedPosition {
  double time_s;
  Eigen::Vector3d p;
};

std::vector<TimedPosition> ReadTum(const std::filesystem::path& path) {
  std::vector<TimedPosition> poses;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    TimedPosition t{};
    fields >> t.time_s >> t.p.x() >> t.p.y() >> t.p.z();
    poses.push_back(t);
  }
  return poses;
}

// The largest distance between two trajectories' positions at the same anchors.
double LargestGap(const std::vector<TimedPosition>& a, const std::vector<TimedPosition>& b) {
  EXPECT_EQ(a.size(), b.size());
  double gap = 0.0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) gap = std::max(gap, (a[i].p - b[i].p).norm());
  return gap;
}

// The fraction of `a`'s points with a point of `b` within `radius_m` (a grid of `b` by cells of
// the radius: the 27 cells around a point hold every candidate).
double FractionWithin(const uwscan::perception::PointCloud& a, const uwscan::perception::PointCloud& b,
                      double radius_m) {
  const auto cell = [radius_m](const Eigen::Vector3d& p) {
    return Eigen::Vector3i(static_cast<int>(std::floor(p.x() / radius_m)), static_cast<int>(std::floor(p.y() / radius_m)),
                           static_cast<int>(std::floor(p.z() / radius_m)));
  };
  const auto key = [](const Eigen::Vector3i& c) {
    return (static_cast<std::int64_t>(c.x()) * 73856093) ^ (static_cast<std::int64_t>(c.y()) * 19349663) ^
           (static_cast<std::int64_t>(c.z()) * 83492791);
  };
  std::unordered_map<std::int64_t, std::vector<Eigen::Vector3d>> grid;
  for (std::size_t i = 0; i < b.size(); ++i) grid[key(cell(b.Point(i)))].push_back(b.Point(i));
  std::size_t within = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Eigen::Vector3d p = a.Point(i);
    const Eigen::Vector3i c = cell(p);
    bool found = false;
    for (int dx = -1; dx <= 1 && !found; ++dx) {
      for (int dy = -1; dy <= 1 && !found; ++dy) {
        for (int dz = -1; dz <= 1 && !found; ++dz) {
          const auto it = grid.find(key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == grid.end()) continue;
          for (const Eigen::Vector3d& q : it->second) found = found || (q - p).norm() <= radius_m;
        }
      }
    }
    within += found ? 1 : 0;
  }
  return a.size() == 0 ? 0.0 : static_cast<double>(within) / static_cast<double>(a.size());
}

struct MapOutput {
  uwscan::perception::PointCloud map;
  std::vector<TimedPosition> trajectory;
  nlohmann::json report;
};

MapOutput Map(const std::filesystem::path& log, const std::string& name) {
  const std::filesystem::path ply = TempPath(name + ".ply"), tum = TempPath(name + ".tum"),
                              json = TempPath(name + ".json");
  const CommandRun run = RunUwscan("map " + log.string() + " -o " + ply.string() + " --trajectory " + tum.string() +
                                   " --json " + json.string());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  MapOutput out;
  if (run.exit_code != 0) return out;
  out.map = uwscan::perception::ReadCloud(ply);
  out.trajectory = ReadTum(tum);
  std::ifstream in(json);
  out.report = nlohmann::json::parse(in);
  return out;
}

nlohmann::json CheckBag(const std::filesystem::path& bag) {
  const CommandRun run = RunCommand("/usr/bin/python3 " + SourcePath("tests/ros/check_bag.py") + " " + bag.string());
  EXPECT_EQ(run.exit_code, 0) << run.output;
  return run.exit_code == 0 ? nlohmann::json::parse(run.output) : nlohmann::json::object();
}

// JSON compared as text: gtest cannot print a json value when a comparison fails.
std::string Dump(const nlohmann::json& value) { return value.dump(); }

constexpr double kVoxelDiagonal_m = 0.005 * 1.7320508075688772;

}  // namespace

// ROS's own reader finds in the exported bag what a vehicle records: every frame as an image in
// the camera frame, the odometry and its TF in time order, the mount and the dive description.
TEST(CliRos, ExportedBagReadsWithRosOwnReader) {
  const nlohmann::json topics = CheckBag(ShortBag());
  ASSERT_TRUE(topics.contains("/uwscan/frames")) << topics.dump();
  const nlohmann::json& frames = topics["/uwscan/frames"];
  EXPECT_EQ(Dump(frames["type"]), Dump("sensor_msgs/Image"));
  EXPECT_EQ(Dump(frames["count"]), Dump(1989));  // 39 sweeps of 51 frames at 100 frames/s
  EXPECT_EQ(Dump(frames["frame_ids"]), Dump(nlohmann::json::array({"uwscan_camera"})));
  EXPECT_TRUE(frames["ordered"].get<bool>());
  const nlohmann::json& odometry = topics["/navigation/odometry"];
  EXPECT_EQ(Dump(odometry["type"]), Dump("nav_msgs/Odometry"));
  EXPECT_GT(odometry["count"].get<int>(), 100);
  EXPECT_TRUE(odometry["ordered"].get<bool>());
  EXPECT_EQ(Dump(odometry["frame_ids"]), Dump(nlohmann::json::array({"odom"})));
  EXPECT_EQ(Dump(odometry["children"]), Dump(nlohmann::json::array({"base_link"})));
  EXPECT_EQ(Dump(topics["/tf"]["count"]), Dump(odometry["count"]));
  EXPECT_EQ(Dump(topics["/tf_static"]["children"]), Dump(nlohmann::json::array({"base_link uwscan_camera"})));
  EXPECT_EQ(Dump(topics["/uwscan/dive"]["type"]), Dump("std_msgs/String"));
  // Stamps are ROS time (the log's creation), not the dive's clock that starts at 0.
  EXPECT_GT(frames["first_stamp"].get<double>(), 1.6e9);
  EXPECT_NEAR(frames["last_stamp"].get<double>() - frames["first_stamp"].get<double>(), 19.88, 1e-6);
}

// simulate -> bag export -> bag import -> map maps as map on the original log: the profiles carry
// the peaks to 1/64 px and the stamps to the nanosecond, so the two agree to well under the map's
// voxel and a millimetre along the trajectory.
TEST(CliRos, BagRoundTripMapsLikeTheOriginalLog) {
  const std::filesystem::path imported = TempPath("imported.db");
  const CommandRun run = RunUwscan("bag import " + ShortBag().string() + " -o " + imported.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("1989 frames"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("/tf_static base_link -> uwscan_camera"), std::string::npos) << run.output;
  const MapOutput original = Map(ShortDive(), "original");
  const MapOutput round_trip = Map(imported, "round_trip");
  ASSERT_GT(original.map.size(), 1000u);
  EXPECT_LT(LargestGap(original.trajectory, round_trip.trajectory), 0.001);
  EXPECT_GE(FractionWithin(round_trip.map, original.map, kVoxelDiagonal_m), 0.999);
  EXPECT_GE(FractionWithin(original.map, round_trip.map, kVoxelDiagonal_m), 0.999);
  const nlohmann::json& a = original.report["figures"];
  const nlohmann::json& b = round_trip.report["figures"];
  for (const char* count : {"submaps", "frames_mapped", "loops_accepted", "loops_rejected", "registrations"}) {
    EXPECT_EQ(Dump(a[count]), Dump(b[count])) << count;
  }
  EXPECT_EQ(Dump(b["navigation_noise_assumed"]), "false");  // the noise model travelled in the bag
}

// Bags that cannot make a dive log are refused with one line naming what is wrong, and no log.
TEST(CliRos, ImportRefusesUnusableBagsByName) {
  const std::filesystem::path no_odometry = TempPath("no_odometry.bag");
  ASSERT_EQ(RunCommand("rosbag filter " + ShortBag().string() + " " + no_odometry.string() +
                       " \"topic != '/navigation/odometry'\"")
                .exit_code,
            0);
  const std::filesystem::path log = TempPath("refused.db");
  CommandRun run = RunUwscan("bag import " + no_odometry.string() + " -o " + log.string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("no navigation on topic /navigation/odometry"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(log));

  run = RunUwscan("bag import " + ShortBag().string() + " -o " + log.string() + " --frames-topic /camera/image");
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("no camera frames on topic /camera/image"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("/uwscan/frames (sensor_msgs/Image)"), std::string::npos) << run.output;

  run = RunUwscan("bag import " + ShortBag().string() + " -o " + log.string() + " --dive-topic /nothing");
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("--scanner"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(log));

  // A bag cut short (a copy interrupted): refused, nothing written.
  const std::filesystem::path cut = TempPath("cut.bag");
  std::filesystem::copy_file(ShortBag(), cut);
  std::filesystem::resize_file(cut, std::filesystem::file_size(cut) / 2);
  run = RunUwscan("bag import " + cut.string() + " -o " + log.string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find(cut.string()), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(log));

  // An existing log is never overwritten.
  std::ofstream(log) << "precious";
  run = RunUwscan("bag import " + ShortBag().string() + " -o " + log.string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  std::ifstream in(log);
  std::string content;
  in >> content;
  EXPECT_EQ(content, "precious");
}

// The node on a played bag maps as `map` does offline on the same dive: the same submaps, the
// trajectory within a millimetre, the map within the voxel's diagonal; every frame and
// navigation sample logged; its SLAM path (read back from what it published) beats dead
// reckoning as map's does.
TEST(CliRos, NodeMapsAPlayedBagAsMapDoesOffline) {
  const std::filesystem::path out = TempPath("node");
  const CommandRun run = RunCommand(SourcePath("tests/ros/replay_dive.sh") + " " + UWSCAN_BIN + " " +
                                    ShortBag().string() + " " + out.string() + " --idle-stop-s 3");
  std::ifstream log_file(out / "node.log");
  const std::string node_log((std::istreambuf_iterator<char>(log_file)), std::istreambuf_iterator<char>());
  ASSERT_EQ(run.exit_code, 0) << run.output << node_log;
  std::ifstream json_file(out / "node.json");
  const nlohmann::json node = nlohmann::json::parse(json_file);
  EXPECT_EQ(Dump(node["frames_received"]), Dump(1989)) << node.dump();
  EXPECT_EQ(Dump(node["frames_logged"]), Dump(1989));
  EXPECT_EQ(Dump(node["frames_skipped"]), Dump(0));
  EXPECT_EQ(Dump(node["frames_mapped"]), Dump(1989));
  EXPECT_TRUE(node["scanner_from_dive_description"].get<bool>());
  EXPECT_GT(node["sweeps_published"].get<int>(), 30);

  const MapOutput offline = Map(ShortDive(), "offline");
  const std::vector<TimedPosition> online = ReadTum(out / "node.tum");
  ASSERT_EQ(online.size(), offline.trajectory.size());
  EXPECT_LT(LargestGap(online, offline.trajectory), 0.001);
  const uwscan::perception::PointCloud node_map = uwscan::perception::ReadCloud(out / "node.ply");
  EXPECT_GE(FractionWithin(node_map, offline.map, kVoxelDiagonal_m), 0.999);
  EXPECT_GE(FractionWithin(offline.map, node_map, kVoxelDiagonal_m), 0.999);

  // The node's own log maps too, with navigation (it recorded every odometry sample).
  EXPECT_EQ(Dump(node["navigation_logged"]), Dump(node["navigation_samples"]));
  const MapOutput relogged = Map(out / "node.db", "relogged");
  EXPECT_LT(LargestGap(relogged.trajectory, offline.trajectory), 0.001);

  // What it published, read by ROS's own reader: the final SLAM path at every anchor.
  const nlohmann::json published = CheckBag(out / "published.bag");
  ASSERT_TRUE(published.contains("/uwscan/path")) << published.dump().substr(0, 2000);
  EXPECT_EQ(Dump(published["/uwscan/path"]["frame_ids"]), Dump(nlohmann::json::array({"map"})));
  EXPECT_EQ(Dump(published["/uwscan/sweep"]["frame_ids"]), Dump(nlohmann::json::array({"uwscan_camera"})));
  EXPECT_EQ(Dump(published["/uwscan/map"]["type"]), Dump("sensor_msgs/PointCloud2"));
  EXPECT_EQ(Dump(published["/uwscan/pose"]["type"]), Dump("geometry_msgs/PoseWithCovarianceStamped"));
  const nlohmann::json& transforms = published["/tf"]["children"];  // the bag's odom -> base_link too
  EXPECT_NE(std::find(transforms.begin(), transforms.end(), "map odom"), transforms.end()) << transforms.dump();
  const nlohmann::json& path = published["/uwscan/path"]["last_path"];
  ASSERT_EQ(path.size(), online.size());
  for (std::size_t i = 0; i < online.size(); ++i) {
    const Eigen::Vector3d p(path[i][1].get<double>(), path[i][2].get<double>(), path[i][3].get<double>());
    EXPECT_LT((p - online[i].p).norm(), 1e-6) << "anchor " << i;
  }
}
