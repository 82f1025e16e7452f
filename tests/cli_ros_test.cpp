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

#include "mapping/log/dive_log.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "perception/cloud/point_cloud.hpp"
#include "tests/cli_run.hpp"

namespace {

using uwscan::test::CommandRun;
using uwscan::test::RunCommand;
using uwscan::test::RunUwscan;

std::string SourcePath(const std::string& relative) {
  return std::string(UWSCAN_SOURCE_DIR) + "/" + relative;
}

std::filesystem::path TempPath(const std::string& name) { return uwscan::test::ScratchPath(name); }

// The short inspection dive (20 s, one lap with drifting navigation), simulated once.
// The short dive's scene as built (simulate --design), beside it.
std::filesystem::path ShortDesign() { return TempPath("short_design.ply"); }

const std::filesystem::path& ShortDive() {
  static const std::filesystem::path log = [] {
    const std::filesystem::path path = TempPath("short.db");
    const CommandRun run =
        RunUwscan("simulate " + SourcePath("data/scenes/inspection_short.yaml") + " -o " +
                  path.string() + " --design " + ShortDesign().string());
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
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    gap = std::max(gap, (a[i].p - b[i].p).norm());
  return gap;
}

// The fraction of `a`'s points with a point of `b` within `radius_m` (a grid of `b` by cells of
// the radius: the 27 cells around a point hold every candidate).
double FractionWithin(const uwscan::perception::PointCloud& a,
                      const uwscan::perception::PointCloud& b, double radius_m) {
  const auto cell = [radius_m](const Eigen::Vector3d& p) {
    return Eigen::Vector3i(static_cast<int>(std::floor(p.x() / radius_m)),
                           static_cast<int>(std::floor(p.y() / radius_m)),
                           static_cast<int>(std::floor(p.z() / radius_m)));
  };
  const auto key = [](const Eigen::Vector3i& c) {
    return (static_cast<std::int64_t>(c.x()) * 73856093) ^
           (static_cast<std::int64_t>(c.y()) * 19349663) ^
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
  const CommandRun run = RunUwscan("map " + log.string() + " -o " + ply.string() +
                                   " --trajectory " + tum.string() + " --json " + json.string());
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
  const CommandRun run =
      RunCommand("/usr/bin/python3 " + SourcePath("tests/ros/check_bag.py") + " " + bag.string());
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
  EXPECT_EQ(Dump(topics["/tf_static"]["children"]),
            Dump(nlohmann::json::array({"base_link uwscan_camera"})));
  EXPECT_EQ(Dump(topics["/uwscan/dive"]["type"]), Dump("std_msgs/String"));
  // Stamps are ROS time (the log's creation), not the dive's clock that starts at 0.
  EXPECT_GT(frames["first_stamp"].get<double>(), 1.6e9);
  EXPECT_NEAR(frames["last_stamp"].get<double>() - frames["first_stamp"].get<double>(), 19.88,
              1e-6);
}

// simulate -> bag export -> bag import -> map maps as map on the original log: the profiles carry
// the peaks to 1/64 px and the stamps to the nanosecond, so the two agree to well under the map's
// voxel and a millimetre along the trajectory.
TEST(CliRos, BagRoundTripMapsLikeTheOriginalLog) {
  const std::filesystem::path imported = TempPath("imported.db");
  const CommandRun run =
      RunUwscan("bag import " + ShortBag().string() + " -o " + imported.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("1989 frames"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("/tf_static base_link -> uwscan_camera"), std::string::npos)
      << run.output;
  const MapOutput original = Map(ShortDive(), "original");
  const MapOutput round_trip = Map(imported, "round_trip");
  ASSERT_GT(original.map.size(), 1000u);
  EXPECT_LT(LargestGap(original.trajectory, round_trip.trajectory), 0.001);
  EXPECT_GE(FractionWithin(round_trip.map, original.map, kVoxelDiagonal_m), 0.999);
  EXPECT_GE(FractionWithin(original.map, round_trip.map, kVoxelDiagonal_m), 0.999);
  const nlohmann::json& a = original.report["figures"];
  const nlohmann::json& b = round_trip.report["figures"];
  for (const char* count :
       {"submaps", "frames_mapped", "loops_accepted", "loops_rejected", "registrations"}) {
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
  EXPECT_NE(run.output.find("no navigation on topic /navigation/odometry"), std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(log));

  run = RunUwscan("bag import " + ShortBag().string() + " -o " + log.string() +
                  " --frames-topic /camera/image");
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("no camera frames on topic /camera/image"), std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("/uwscan/frames (sensor_msgs/Image)"), std::string::npos) << run.output;

  run = RunUwscan("bag import " + ShortBag().string() + " -o " + log.string() +
                  " --dive-topic /nothing");
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
// reckoning as map's does. The bag plays at half speed: what is tested is that the node maps as
// `map` does, and at full speed the live path, which skips frames when the CPU falls behind, kept
// up only when the machine was not busy with other tests (bench/ros measures its speed).
TEST(CliRos, NodeMapsAPlayedBagAsMapDoesOffline) {
  const std::filesystem::path out = TempPath("node");
  const CommandRun run =
      RunCommand(SourcePath("tests/ros/replay_dive.sh") + " " + UWSCAN_BIN + " " +
                 ShortBag().string() + " " + out.string() + " -r 0.5 -- --idle-stop-s 3");
  std::ifstream log_file(out / "node.log");
  const std::string node_log((std::istreambuf_iterator<char>(log_file)),
                             std::istreambuf_iterator<char>());
  ASSERT_EQ(run.exit_code, 0) << run.output << node_log;
  std::ifstream json_file(out / "node.json");
  const nlohmann::json node = nlohmann::json::parse(json_file);
  EXPECT_EQ(Dump(node["frames_received"]), Dump(1989)) << node.dump();
  EXPECT_EQ(Dump(node["frames_logged"]), Dump(1989));
  EXPECT_EQ(Dump(node["frames_skipped"]), Dump(0));
  EXPECT_EQ(Dump(node["frames_mapped"]), Dump(1989));
  EXPECT_TRUE(node["scanner_from_dive_description"].get<bool>());
  EXPECT_GT(node["sweeps_published"].get<int>(), 30);
  // The 20 s dive at half speed: its sweeps' latencies in the minute or two they came in.
  const nlohmann::json& minutes = node["sweep_latency_by_minute"];
  ASSERT_TRUE(minutes.is_array() && !minutes.empty() && minutes.size() <= 2) << minutes.dump();
  int sweeps = 0;
  for (const nlohmann::json& m : minutes) sweeps += m["sweeps"].get<int>();
  EXPECT_EQ(sweeps, node["sweeps_published"].get<int>());
  EXPECT_GT(minutes[0]["p95_s"].get<double>(), 0.0);

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
  EXPECT_EQ(Dump(published["/uwscan/sweep"]["frame_ids"]),
            Dump(nlohmann::json::array({"uwscan_camera"})));
  EXPECT_EQ(Dump(published["/uwscan/map"]["type"]), Dump("sensor_msgs/PointCloud2"));
  EXPECT_EQ(Dump(published["/uwscan/map"]["last_fields"]),
            Dump(nlohmann::json::array({"x", "y", "z"})));
  // The last map published (the publishing thread's, after the maps of the dive) is the map
  // written (NED axes: the same coordinates).
  EXPECT_GT(published["/uwscan/map"]["count"].get<int>(), 1);
  EXPECT_EQ(Dump(published["/uwscan/map"]["last_points"]), Dump(node_map.size()));
  const Eigen::Vector3d node_map_centroid = uwscan::perception::Centroid(node_map);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(published["/uwscan/map"]["last_centroid"][k].get<double>(), node_map_centroid(k),
                1e-4);
  }
  EXPECT_EQ(Dump(published["/uwscan/pose"]["type"]),
            Dump("geometry_msgs/PoseWithCovarianceStamped"));
  const nlohmann::json& transforms =
      published["/tf"]["children"];  // the bag's odom -> base_link too
  EXPECT_NE(std::find(transforms.begin(), transforms.end(), "map odom"), transforms.end())
      << transforms.dump();
  const nlohmann::json& path = published["/uwscan/path"]["last_path"];
  ASSERT_EQ(path.size(), online.size());
  for (std::size_t i = 0; i < online.size(); ++i) {
    const Eigen::Vector3d p(path[i][1].get<double>(), path[i][2].get<double>(),
                            path[i][3].get<double>());
    EXPECT_LT((p - online[i].p).norm(), 1e-6) << "anchor " << i;
  }
}

namespace {

struct NodeRun {
  CommandRun run;
  nlohmann::json report;  // node.json, empty when the node wrote none
  std::string log;        // the node's output
};

// Plays `bag` into the node (tests/ros/replay_dive.sh) with `environment` (fault settings).
NodeRun ReplayIntoNode(const std::filesystem::path& bag, const std::string& name,
                       const std::string& environment,
                       const std::string& node_options = "--idle-stop-s 3") {
  const std::filesystem::path out = TempPath(name);
  NodeRun r;
  r.run = RunCommand(environment + " " + SourcePath("tests/ros/replay_dive.sh") + " " + UWSCAN_BIN +
                     " " + bag.string() + " " + out.string() + " " + node_options);
  std::ifstream log_file(out / "node.log");
  r.log.assign(std::istreambuf_iterator<char>(log_file), std::istreambuf_iterator<char>());
  std::ifstream json_file(out / "node.json");
  if (json_file) r.report = nlohmann::json::parse(json_file);
  return r;
}

std::int64_t LogFrames(const std::filesystem::path& log) {
  const CommandRun check = RunUwscan("log check " + log.string());
  EXPECT_EQ(check.exit_code, 0) << check.output;
  const std::size_t at = check.output.find("frames: ");
  return at == std::string::npos ? -1 : std::stoll(check.output.substr(at + 8));
}

}  // namespace

// The ROS master dies five seconds into the dive and a new one starts two seconds later: the
// node keeps receiving from the player it is connected to, registers again, and loses no frame.
// Given the scene as built (--reference), the published map carries each point's deviation from
// it, read back with ROS's own reader: most of the map lies within the live threshold (NaN).
TEST(CliRos, NodePublishesTheMapsDeviationFromAReference) {
  ShortDive();  // simulated with its design beside it
  const NodeRun r = ReplayIntoNode(ShortBag(), "reference", "",
                                   "--idle-stop-s 3 --reference " + ShortDesign().string());
  ASSERT_EQ(r.run.exit_code, 0) << r.run.output << r.log;
  const nlohmann::json published = CheckBag(TempPath("reference") / "published.bag");
  EXPECT_EQ(Dump(published["/uwscan/map"]["last_fields"]),
            Dump(nlohmann::json::array({"x", "y", "z", "deviation"})));
  EXPECT_LT(published["/uwscan/map"]["last_finite_share"].get<double>(), 0.2);
}

TEST(CliRos, NodeLosesNoFrameWhenTheMasterRestarts) {
  const NodeRun r = ReplayIntoNode(ShortBag(), "master_restart", "MASTER_DOWN_AT=5");
  ASSERT_EQ(r.run.exit_code, 0) << r.run.output << r.log;
  EXPECT_EQ(Dump(r.report["frames_received"]), Dump(1989)) << r.report.dump();
  EXPECT_EQ(Dump(r.report["frames_logged"]), Dump(1989));
  EXPECT_GE(r.report["reregistrations"].get<int>(), 1) << r.log;
  EXPECT_EQ(LogFrames(TempPath("master_restart") / "node.db"), 1989);
}

// SIGINT mid-dive: the node stops, every frame it received is in its log, and it says why.
TEST(CliRos, SigintStopsTheNodeWithEveryReceivedFrameLogged) {
  const NodeRun r = ReplayIntoNode(ShortBag(), "sigint", "SIGINT_AT=6");
  ASSERT_EQ(r.run.exit_code, 0) << r.run.output << r.log;
  const std::int64_t received = r.report["frames_received"].get<std::int64_t>();
  EXPECT_GT(received, 100) << r.report.dump();
  EXPECT_LT(received, 1989);
  EXPECT_EQ(r.report["frames_logged"].get<std::int64_t>(), received);
  EXPECT_EQ(r.report["stop_reason"].get<std::string>(), "stop requested");
  EXPECT_EQ(LogFrames(TempPath("sigint") / "node.db"), received);
}

// The navigation stops half-way: the frames after it are logged but not mapped, counted and
// said so, and they do not pile up (MapperOptions::navigation_latency_s); the node ends cleanly.
TEST(CliRos, FramesAfterTheNavigationStoppedAreLoggedNotMapped) {
  const nlohmann::json topics = CheckBag(ShortBag());
  const double stop_s = topics["/uwscan/frames"]["first_stamp"].get<double>() + 10.0;
  const std::filesystem::path bag = TempPath("navigation_stops.bag");
  ASSERT_EQ(RunCommand("rosbag filter " + ShortBag().string() + " " + bag.string() +
                       " \"topic != '/navigation/odometry' or m.header.stamp.to_sec() < " +
                       std::to_string(stop_s) + "\"")
                .exit_code,
            0);
  const NodeRun r = ReplayIntoNode(bag, "navigation_stops", "");
  ASSERT_EQ(r.run.exit_code, 0) << r.run.output << r.log;
  EXPECT_EQ(Dump(r.report["frames_logged"]), Dump(1989)) << r.report.dump();
  const std::int64_t left_out = r.report["frames_without_navigation"].get<std::int64_t>();
  EXPECT_GT(left_out, 900);  // the last ten seconds, at 100 frames/s
  EXPECT_LT(left_out, 1100);
  EXPECT_EQ(r.report["frames_mapped"].get<std::int64_t>() + left_out, 1989);
  EXPECT_NE(r.log.find(std::to_string(left_out) + " frames logged but not mapped: no navigation"),
            std::string::npos)
      << r.log;
}

// A dive and its map report in one bag: RViz replays the frames and navigation, the map, and the
// SLAM, navigation and true paths growing anchor by anchor, on the node's topics and stamps.
TEST(CliRos, ADiveAndItsMapReportExportTogether) {
  const MapOutput mapped = Map(ShortDive(), "for_export");
  const std::filesystem::path bag = TempPath("dive_and_map.bag");
  const CommandRun run = RunUwscan("bag export " + ShortDive().string() + " " +
                                   TempPath("for_export.json").string() + " -o " + bag.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json topics = CheckBag(bag);
  const std::size_t anchors = mapped.trajectory.size();
  EXPECT_EQ(Dump(topics["/uwscan/map"]["count"]), Dump(1));
  EXPECT_EQ(Dump(topics["/uwscan/path"]["count"]), Dump(anchors));
  EXPECT_EQ(Dump(topics["/uwscan/truth_path"]["count"]), Dump(anchors));
  EXPECT_EQ(Dump(topics["/uwscan/pose"]["count"]), Dump(anchors));
  EXPECT_EQ(Dump(topics["/uwscan/frames"]["count"]), Dump(1989));
  // The map's anchors at the frames' stamps: one clock for the dive and its map.
  const double origin_s = topics["/uwscan/frames"]["first_stamp"].get<double>();
  const nlohmann::json& path = topics["/uwscan/path"]["last_path"];
  ASSERT_EQ(path.size(), anchors);
  for (std::size_t i = 0; i < anchors; ++i) {
    EXPECT_NEAR(path[i][0].get<double>() - origin_s, mapped.trajectory[i].time_s, 1e-6);
    const Eigen::Vector3d p(path[i][1].get<double>(), path[i][2].get<double>(),
                            path[i][3].get<double>());
    EXPECT_LT((p - mapped.trajectory[i].p).norm(), 1e-9);
  }
  const CommandRun tum = RunUwscan("bag export " + TempPath("for_export.tum").string() + " -o " +
                                   TempPath("refused.bag").string());
  EXPECT_EQ(tum.exit_code, 1) << tum.output;
  EXPECT_FALSE(std::filesystem::exists(TempPath("refused.bag")));
}

// The demo scene (a valve, a flanged pipe) simulated, a database of its objects built and the
// scene recognised offline (`uwscan recognize --json`), once.
struct OfflineRecognition {
  std::filesystem::path db, log, report;
};
const OfflineRecognition& RecognisedDemo() {
  static const OfflineRecognition r = [] {
    OfflineRecognition o{TempPath("objects.db"), TempPath("demo.db"), TempPath("offline.json")};
    CommandRun run = RunUwscan("build-db valve_wheel flange pipe --views 16 -o " + o.db.string());
    EXPECT_EQ(run.exit_code, 0) << run.output;
    EXPECT_EQ(
        RunUwscan("simulate " + SourcePath("data/scenes/default.yaml") + " -o " + o.log.string())
            .exit_code,
        0);
    run = RunUwscan("recognize " + o.log.string() + " --db " + o.db.string() + " --json " +
                    o.report.string());
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return o;
  }();
  return r;
}

// Recognition on the vehicle: the node's published sweep of the demo scene searched by
// `uwscan ros recognize`, which finds what `uwscan recognize` finds in the same sweep offline, at
// the same place, and publishes it with standard messages.
TEST(CliRos, RecognitionNodeFindsWhatRecognizeFindsOffline) {
  const OfflineRecognition& demo = RecognisedDemo();
  const std::filesystem::path db = demo.db, bag = TempPath("demo.bag"), offline = demo.report;
  ASSERT_EQ(RunUwscan("bag export " + demo.log.string() + " -o " + bag.string()).exit_code, 0);
  const NodeRun r = ReplayIntoNode(bag, "recognition", "RECOGNIZE_DB=" + db.string());
  ASSERT_EQ(r.run.exit_code, 0) << r.run.output << r.log;

  std::ifstream offline_file(offline), online_file(TempPath("recognition") / "recognition.json");
  const nlohmann::json expected = nlohmann::json::parse(offline_file);
  const nlohmann::json online = nlohmann::json::parse(online_file);
  EXPECT_EQ(online["sweeps_recognised"].get<int>(), 1) << online.dump();
  std::vector<std::string> expected_ids;
  std::vector<Eigen::Vector3d> expected_positions;
  for (const nlohmann::json& o : expected["objects"]) {
    if (o["id"] == "unknown") continue;
    expected_ids.push_back(o["id"].get<std::string>());
    const nlohmann::json& p = o["T_S_O"]["position_m"];
    expected_positions.emplace_back(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
  }
  ASSERT_GE(expected_ids.size(), 2u) << expected.dump().substr(0, 2000);
  for (const std::string& id : expected_ids)
    EXPECT_TRUE(online["objects"].contains(id)) << id << online.dump();

  const nlohmann::json published = CheckBag(TempPath("recognition") / "published.bag");
  const nlohmann::json& labels = published["/uwscan/objects"]["last_labels"];
  EXPECT_EQ(labels.size(), expected_ids.size()) << labels.dump();
  const nlohmann::json& positions = published["/uwscan/object_poses"]["positions"];
  ASSERT_EQ(positions.size(), expected_positions.size()) << positions.dump();
  for (const Eigen::Vector3d& e : expected_positions) {
    double nearest = 1e9;
    for (const nlohmann::json& p : positions) {
      nearest = std::min(
          nearest,
          (Eigen::Vector3d(p[0].get<double>(), p[1].get<double>(), p[2].get<double>()) - e).norm());
    }
    EXPECT_LT(nearest, 0.005) << "an object offline at " << e.transpose();
  }
  EXPECT_EQ(Dump(published["/uwscan/object_poses"]["frame_ids"]),
            Dump(nlohmann::json::array({"uwscan_camera"})));
}

namespace {

// The short dive's bag as a vehicle in REP 103's default axes records it (tests/ros/enu_bag.py).
const std::filesystem::path& EnuBag() {
  static const std::filesystem::path bag = [] {
    const std::filesystem::path path = TempPath("enu.bag");
    const CommandRun run = RunCommand("/usr/bin/python3 " + SourcePath("tests/ros/enu_bag.py") +
                                      " " + ShortBag().string() + " " + path.string());
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return path;
  }();
  return bag;
}

// The largest gap between two logs' navigation samples (translation, m, plus rotation, rad), and
// between their mounts; infinity when their counts differ.
double NavigationGap(const std::filesystem::path& a_log, const std::filesystem::path& b_log) {
  const uwscan::mapping::DiveLogReader a(a_log), b(b_log);
  const std::vector<uwscan::mapping::NavigationRecord> nav_a = a.ReadNavigation(),
                                                       nav_b = b.ReadNavigation();
  if (nav_a.size() != nav_b.size() || !a.vehicle_mount() || !b.vehicle_mount()) return INFINITY;
  const auto gap = [](const Eigen::Isometry3d& x, const Eigen::Isometry3d& y) {
    return (x.translation() - y.translation()).norm() + (x.linear() - y.linear()).norm();
  };
  double largest = gap(*a.vehicle_mount(), *b.vehicle_mount());
  for (std::size_t i = 0; i < nav_a.size(); ++i) {
    largest = std::max({largest, std::abs(nav_a[i].time_s - nav_b[i].time_s),
                        gap(nav_a[i].T_W_V, nav_b[i].T_W_V)});
  }
  return largest;
}

}  // namespace

// A vehicle whose navigation is in ENU with a forward-left-up base_link (REP 103's default, as
// robot_localization publishes it), read from its odometry or from /tf alone: imported with
// --navigation-axes enu, the log holds the original dive's navigation and mount; taken as NED it
// does not; a /tf without the navigation's frames is refused by name.
TEST(CliRos, ImportTakesNavigationInEnuAxesAndFromTf) {
  const std::filesystem::path original = TempPath("original_nav.db");
  ASSERT_EQ(RunUwscan("bag import " + ShortBag().string() + " -o " + original.string()).exit_code,
            0);
  for (const char* source : {"odometry", "tf"}) {
    const std::filesystem::path log = TempPath(std::string("enu_") + source + ".db");
    const CommandRun run = RunUwscan("bag import " + EnuBag().string() + " -o " + log.string() +
                                     " --navigation-axes enu --navigation " + source);
    ASSERT_EQ(run.exit_code, 0) << run.output;
    EXPECT_LT(NavigationGap(original, log), 1e-9) << source;
  }
  const std::filesystem::path as_ned = TempPath("enu_as_ned.db");
  ASSERT_EQ(RunUwscan("bag import " + EnuBag().string() + " -o " + as_ned.string()).exit_code, 0);
  EXPECT_GT(NavigationGap(original, as_ned), 1.0);
  const std::filesystem::path refused = TempPath("enu_refused.db");
  const CommandRun run = RunUwscan("bag import " + EnuBag().string() + " -o " + refused.string() +
                                   " --navigation tf --odom-frame world_enu");
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("no world_enu -> base_link transform on /tf"), std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(refused));
}

// The node on that vehicle, its navigation from /tf alone in ENU/FLU: it logs and maps the dive
// as it does from NED odometry, and publishes its path in the vehicle's ENU axes.
TEST(CliRos, NodeTakesNavigationFromTfInEnuAxes) {
  const NodeRun r = ReplayIntoNode(EnuBag(), "enu_tf", "",
                                   "--idle-stop-s 3 _navigation_source:=tf _navigation_axes:=enu");
  ASSERT_EQ(r.run.exit_code, 0) << r.run.output << r.log;
  EXPECT_EQ(Dump(r.report["frames_mapped"]), Dump(1989)) << r.report.dump();
  EXPECT_NE(r.log.find("navigation on /tf (odom -> base_link) in ENU/FLU axes"), std::string::npos)
      << r.log;
  const std::filesystem::path out = TempPath("enu_tf");
  EXPECT_LT(NavigationGap(ShortDive(), out / "node.db"),
            1e-6);  // stamps in ROS time: ~1e-7 s steps
  const MapOutput offline = Map(ShortDive(), "offline_for_enu");
  const std::vector<TimedPosition> online = ReadTum(out / "node.tum");
  EXPECT_LT(LargestGap(online, offline.trajectory), 0.001);
  const nlohmann::json published = CheckBag(out / "published.bag");
  const nlohmann::json& path = published["/uwscan/path"]["last_path"];
  ASSERT_EQ(path.size(), online.size());
  for (std::size_t i = 0; i < online.size(); ++i) {
    const Eigen::Vector3d enu(online[i].p.y(), online[i].p.x(), -online[i].p.z());
    const Eigen::Vector3d p(path[i][1].get<double>(), path[i][2].get<double>(),
                            path[i][3].get<double>());
    EXPECT_LT((p - enu).norm(), 1e-6) << "anchor " << i;
  }
}

// A recognition report exported to a bag replays what was recognised as the recognition node
// publishes it: the scan on the sweep topic, each object's pose (where the report puts it) with a
// covariance, its grasps and its model and label, in the camera frame at the sweep's middle.
TEST(CliRos, ARecognitionReportExportsAsTheRecognitionNodePublishes) {
  const OfflineRecognition& demo = RecognisedDemo();
  const std::filesystem::path bag = TempPath("recognition_report.bag");
  const CommandRun run = RunUwscan("bag export " + demo.report.string() + " -o " + bag.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream report_file(demo.report);
  const nlohmann::json report = nlohmann::json::parse(report_file);
  std::vector<Eigen::Vector3d> positions;
  std::size_t grasps = 0;
  for (const nlohmann::json& o : report["objects"]) {
    if (o["id"] == "unknown") continue;
    const nlohmann::json& p = o["T_S_O"]["position_m"];
    positions.emplace_back(p[0].get<double>(), p[1].get<double>(), p[2].get<double>());
    grasps += o["grasps"].size();
  }
  ASSERT_GE(positions.size(), 2u);
  const nlohmann::json topics = CheckBag(bag);
  EXPECT_EQ(Dump(topics["/uwscan/sweep"]["count"]), Dump(1));
  EXPECT_GT(topics["/uwscan/sweep"]["last_points"].get<int>(), 1000)
      << topics.dump().substr(0, 2000);
  const nlohmann::json& poses = topics["/uwscan/object_poses"]["positions"];
  ASSERT_EQ(poses.size(), positions.size()) << poses.dump();
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const Eigen::Vector3d p(poses[i][0].get<double>(), poses[i][1].get<double>(),
                            poses[i][2].get<double>());
    EXPECT_LT((p - positions[i]).norm(), 1e-9) << "object " << i;
  }
  EXPECT_EQ(topics["/uwscan/objects"]["last_labels"].size(), positions.size());
  EXPECT_EQ(Dump(topics["/uwscan/grasps"]["last_poses"]), Dump(grasps));
  for (const char* topic : {"/uwscan/sweep", "/uwscan/object_poses", "/uwscan/grasps"}) {
    EXPECT_EQ(Dump(topics[topic]["frame_ids"]), Dump(nlohmann::json::array({"uwscan_camera"})))
        << topic;
  }
  // The scan's time: within the simulated dive's frames, on the clock a bag of that dive has.
  const std::filesystem::path dive_bag = TempPath("demo_for_time.bag");
  ASSERT_EQ(RunUwscan("bag export " + demo.log.string() + " -o " + dive_bag.string()).exit_code, 0);
  const nlohmann::json dive = CheckBag(dive_bag);
  const double t = topics["/uwscan/sweep"]["first_stamp"].get<double>();
  EXPECT_GT(t, dive["/uwscan/frames"]["first_stamp"].get<double>());
  EXPECT_LT(t, dive["/uwscan/frames"]["last_stamp"].get<double>());
}

// A vehicle's own bag (tests/ros/vehicle_bag.py): its topic and frame names, frames and
// navigation recorded out of stamp order, TF at 50 Hz, the mount as a chain of static transforms,
// other topics, no dive description. Imported with the scanner's file and the topic names, it
// gives the dive's frames and navigation back, the camera where the chain puts it, and maps.
TEST(CliRos, AVehiclesOwnBagImportsWithItsScannerAndTopicNames) {
  const std::filesystem::path vehicle = TempPath("vehicle.bag");
  const CommandRun rewrite =
      RunCommand("/usr/bin/python3 " + SourcePath("tests/ros/vehicle_bag.py") + " " +
                 ShortBag().string() + " " + vehicle.string());
  ASSERT_EQ(rewrite.exit_code, 0) << rewrite.output;
  const std::filesystem::path log = TempPath("vehicle.db");
  const std::string topics =
      " --frames-topic /girona500/camera/profile --odometry-topic /girona500/navigator/odometry";
  CommandRun run = RunUwscan("bag import " + vehicle.string() + " -o " + log.string() + topics);
  EXPECT_EQ(run.exit_code, 1) << run.output;  // no dive description: the scanner must be given
  EXPECT_NE(run.output.find("--scanner"), std::string::npos) << run.output;
  run = RunUwscan("bag import " + vehicle.string() + " -o " + log.string() + topics +
                  " --scanner " + SourcePath("data/scanners/galvo_binned.yaml"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("girona500/base_link -> girona500/laser_camera"), std::string::npos)
      << run.output;

  const uwscan::mapping::DiveLogReader original(ShortDive()), imported(log);
  ASSERT_EQ(imported.frame_count(), original.frame_count());
  for (std::int64_t i = 0; i < original.frame_count(); i += 97) {
    const uwscan::mapping::FrameRecord a = original.ReadFrame(i), b = imported.ReadFrame(i);
    EXPECT_EQ(a.command, b.command);
    EXPECT_EQ(a.sweep, b.sweep);
    EXPECT_EQ(a.peaks_px.size(), b.peaks_px.size());
  }
  const std::vector<uwscan::mapping::NavigationRecord> nav_a = original.ReadNavigation(),
                                                       nav_b = imported.ReadNavigation();
  ASSERT_EQ(nav_a.size(), nav_b.size());
  // The vehicle's stamps are ROS time: the dive's clock plus the bag's origin, kept as they are.
  const double origin_s = imported.ReadFrame(0).time_s - original.ReadFrame(0).time_s;
  EXPECT_GT(origin_s, 1.6e9);
  for (std::size_t i = 0; i < nav_a.size(); ++i) {
    EXPECT_NEAR(nav_b[i].time_s - origin_s, nav_a[i].time_s, 1e-6);
    EXPECT_TRUE(nav_b[i].T_W_V.isApprox(nav_a[i].T_W_V, 1e-9));
  }
  ASSERT_TRUE(imported.vehicle_mount() && original.vehicle_mount());
  EXPECT_TRUE(imported.vehicle_mount()->isApprox(*original.vehicle_mount(), 1e-9));
  const MapOutput mapped = Map(log, "vehicle");
  EXPECT_EQ(Dump(mapped.report["figures"]["frames_mapped"]), Dump(original.frame_count()));
}

namespace {

// A copy of the short dive's bag with one fault (tests/ros/edit_bag.py).
std::filesystem::path FaultyBag(const std::string& name, const std::string& fault) {
  const std::filesystem::path bag = TempPath(name + ".bag");
  const CommandRun run = RunCommand("/usr/bin/python3 " + SourcePath("tests/ros/edit_bag.py") +
                                    " " + ShortBag().string() + " " + bag.string() + " " + fault);
  EXPECT_EQ(run.exit_code, 0) << run.output;
  return bag;
}

}  // namespace

// Frames of the wrong encoding, or whose stamps go back: refused with one line naming the topic
// and what is wrong, and no log.
TEST(CliRos, ImportRefusesWrongEncodingsAndStampsThatGoBack) {
  const std::filesystem::path log = TempPath("faulty.db");
  CommandRun run =
      RunUwscan("bag import " + FaultyBag("rgb", "encoding rgb8").string() + " -o " + log.string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("/uwscan/frames: image encoding 'rgb8', expected mono8 or mono16"),
            std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(log));
  run = RunUwscan("bag import " + FaultyBag("back", "stamp_back 500").string() + " -o " +
                  log.string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("topic /uwscan/frames: stamp"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("goes back"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("(message 500)"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(log));
}

// The node given frames it cannot read stops with one line naming the topic, exit 1.
TEST(CliRos, NodeRefusesFramesOfTheWrongEncodingByName) {
  const NodeRun r = ReplayIntoNode(FaultyBag("rgb_node", "encoding rgb8"), "rgb_node", "");
  EXPECT_EQ(r.run.exit_code, 1) << r.run.output << r.log;
  EXPECT_NE(r.log.find("uwscan: error: /uwscan/frames: image encoding 'rgb8'"), std::string::npos)
      << r.log;
}

// The camera's topic stops while the navigation goes on: the node says so, and (with
// --idle-stop-s) ends with every frame it received logged and mapped.
TEST(CliRos, NodeSaysWhenTheFramesStop) {
  const NodeRun r = ReplayIntoNode(FaultyBag("frames_stop", "frames_until 8"), "frames_stop", "",
                                   "--idle-stop-s 6");
  ASSERT_EQ(r.run.exit_code, 0) << r.run.output << r.log;
  EXPECT_NE(r.log.find("no frame on /uwscan/frames for"), std::string::npos) << r.log;
  const std::int64_t received = r.report["frames_received"].get<std::int64_t>();
  EXPECT_GT(received, 750);
  EXPECT_LT(received, 850);  // 8 s at 100 frames/s
  EXPECT_EQ(r.report["frames_logged"].get<std::int64_t>(), received);
  EXPECT_EQ(r.report["frames_mapped"].get<std::int64_t>(), received);
  EXPECT_EQ(r.report["stop_reason"].get<std::string>().rfind("no frame for 6", 0), 0u)
      << r.report.dump();
}

// bench ros writes every figure its JSON promises; at the seed camera's 339 frames/s the node
// loses no frame.
TEST(CliRos, RosBenchWritesItsFiguresAndLosesNoFrame) {
  const std::filesystem::path json = TempPath("bench_ros.json");
  const CommandRun run =
      RunUwscan("bench ros --rates 3.39 --inspect-seconds 5 --json " + json.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream in(json);
  const nlohmann::json r = nlohmann::json::parse(in);
  const nlohmann::json& node = r["node"];
  EXPECT_EQ(node["lost_frames"].get<int>(), 0) << r.dump();
  EXPECT_GT(node["frames_per_s"].get<double>(), 300.0);
  EXPECT_GT(node["latency_s"]["median"].get<double>(), 0.0);
  EXPECT_GE(node["latency_s"]["p95"].get<double>(), node["latency_s"]["median"].get<double>());
  EXPECT_GT(node["peak_rss_bytes"].get<double>(), 1e6);
  const nlohmann::json& memory = node["memory"];
  ASSERT_TRUE(memory.is_object()) << node.dump();
  EXPECT_GT(memory["rss_at_end_bytes"].get<double>(), 1e6);
  EXPECT_LE(memory["rss_at_end_bytes"].get<double>(), node["peak_rss_bytes"].get<double>());
  EXPECT_GE(memory["samples_s_bytes"].size(), 4u);
  EXPECT_GT(r["direct_inspect"]["frames_per_s"].get<double>(), 0.0);
  EXPECT_GT(r["offline_map"]["cpu_s_per_frame"].get<double>(), 0.0);
  EXPECT_TRUE(r["overhead_ratio"].is_number());
}

// bench ros --long-minutes: the long-dive bench's field replayed through the node at its own
// rate, its memory and sweep latency minute by minute, no frame lost.
TEST(CliRos, RosSoakReportsMinuteByMinute) {
  const std::filesystem::path json = TempPath("bench_ros_soak.json");
  const CommandRun run = RunUwscan("bench ros --long-minutes 1 --json " + json.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("minute   1:"), std::string::npos) << run.output;
  std::ifstream in(json);
  const nlohmann::json r = nlohmann::json::parse(in);
  const nlohmann::json& soak = r["soak"];
  EXPECT_EQ(soak["frames_lost"].get<int>(), 0) << r.dump();
  EXPECT_EQ(r["node"]["rate"].get<double>(), 1.0);
  const nlohmann::json& minutes = soak["per_minute"];
  ASSERT_GE(minutes.size(), 1u) << soak.dump();
  // A minute at 100 frames/s and 51 frames a sweep: about 117 sweeps in the first.
  EXPECT_GT(minutes[0]["sweeps"].get<int>(), 100) << soak.dump();
  EXPECT_GT(soak["latency_p95_s"]["first_minute"].get<double>(), 0.0);
  EXPECT_GT(soak["rss_bytes"]["first_minute"].get<double>(), 1e6);
  EXPECT_GT(soak["rss_bytes"]["last_minute"].get<double>(), 1e6);
}

// The node reads the camera itself (the fake camera, profile mode) as `inspect` does, with the
// vehicle's odometry from ROS: every frame received is logged, none is lost on the way, and the
// frames the navigation covers are mapped.
TEST(CliRos, NodeReadsACameraDirectly) {
  const std::filesystem::path out = TempPath("camera_node");
  const CommandRun run =
      RunCommand(SourcePath("tests/ros/camera_node.sh") + " " + UWSCAN_BIN + " " +
                 SourcePath("data/scenes/default.yaml") + " " + out.string() + " 400");
  std::ifstream log_file(out / "node.log");
  const std::string log((std::istreambuf_iterator<char>(log_file)),
                        std::istreambuf_iterator<char>());
  ASSERT_EQ(run.exit_code, 0) << run.output << log;
  std::ifstream json_file(out / "node.json");
  const nlohmann::json r = nlohmann::json::parse(json_file);
  EXPECT_EQ(Dump(r["frames_received"]), Dump(400)) << r.dump();
  EXPECT_EQ(Dump(r["frames_logged"]), Dump(400));
  EXPECT_EQ(Dump(r["camera_lost_frames"]), Dump(0));
  EXPECT_GT(r["frames_mapped"].get<int>(), 300) << r.dump();
  EXPECT_EQ(r["frames_mapped"].get<int>() + r["frames_without_navigation"].get<int>() +
                r["frames_skipped"].get<int>() + r["frames_out_of_order"].get<int>(),
            400);
  EXPECT_NE(log.find("frames from the camera 127.0.0.1"), std::string::npos) << log;
}
