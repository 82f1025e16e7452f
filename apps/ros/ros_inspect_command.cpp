#include "apps/ros/ros_inspect_command.hpp"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli/data_cache.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/malloc_arena.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/output_path.hpp"
#include "apps/cli/reference_options.hpp"
#include "apps/cli/stop_signal.hpp"
#include "apps/ros/ros_arguments.hpp"
#include "apps/ros/ros_recognize_command.hpp"
#include "apps/scanner/camera_frames.hpp"
#include "mapping/slam/trajectory_metrics.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "ros/node/inspection_node.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/temporary_folder.hpp"
#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::app {
namespace {

struct RosInspectArgs {
  std::string camera;  // a camera's address: frames from it instead of the image topic
  std::string scene;   // a simulated camera's scene
  std::string scanner_file;
  std::string log;
  std::string map;
  std::string trajectory;
  std::string json;
  std::int64_t frames = 0;
  double idle_stop_s = 0.0;
  double master_wait_s = 10.0;
  bool force = false;
  LiveReferenceArgs reference;             // the published map carries its deviation from it
  std::vector<std::string> ros_arguments;  // name:=value
};

// The node's private parameters: name, what it sets, its default.
const char* const kParameterHelp =
    "ROS parameters (private, ~name; set them with rosparam, a launch file, or _name:=value "
    "here):\n"
    "  ~frames_topic        camera frames, sensor_msgs/Image with uwscan's payload   "
    "[/uwscan/frames]\n"
    "  ~odometry_topic      the vehicle's navigation, nav_msgs/Odometry             "
    "[/navigation/odometry]\n"
    "  ~dive_topic          dive description (scanner), std_msgs/String, latched     "
    "[/uwscan/dive]\n"
    "  ~navigation_source   odometry (nav_msgs/Odometry) or tf (odom_frame -> base_frame on /tf)  "
    "[odometry]\n"
    "  ~navigation_axes     ned (NED world, forward-right-down vehicle) or enu (ENU, "
    "forward-left-up,\n"
    "                       REP 103's default: the mount read and map, paths, poses published so)  "
    "[ned]\n"
    "  ~map_frame ~odom_frame ~base_frame ~camera_frame   frame names               [map odom "
    "base_link uwscan_camera]\n"
    "  ~scanner             scanner (calibration) file when no dive description comes  []\n"
    "  ~description_wait_s  how long to wait for the dive description, s            [30]\n"
    "  ~mount_wait_s        how long to wait for base_frame -> camera_frame on /tf_static, s  [3]\n"
    "  ~map_period_s        the map and paths are published at most this often (less often "
    "once they take over a tenth of it), s  [2]\n"
    "  ~voxel_m             map voxel, m                                           [0.005]\n"
    "  ~sweeps_per_submap   sweeps grouped into one submap                          [1]\n"
    "  ~whole_solve_lag_s   a long dive's whole-graph solves run beside the mapping, applied "
    "this much dive time later (0: at once, on the mapping thread), s  [10]\n"
    "  ~live_queue          frames waiting for the mapper (a newer frame skips the oldest)  "
    "[1024]\n"
    "  ~frame_queue         frames roscpp holds while the node is busy              [4096]\n"
    "  ~images              image-mode frames: log the images too                   [false]\n"
    "Publishes: ~sweep (/uwscan/sweep, PointCloud2, camera frame), /uwscan/map (PointCloud2, "
    "latched),\n"
    "/uwscan/path and /uwscan/navigation_path (nav_msgs/Path, map frame), /uwscan/pose\n"
    "(PoseWithCovarianceStamped), map -> odom on /tf, in the navigation's axes "
    "(~navigation_axes).\n"
    "ROS 1 has no authentication: the node binds to ROS_IP (or ROS_HOSTNAME); set it to the "
    "vehicle's\n"
    "private interface, never leave it to all interfaces on an open network.";

ros::InspectionNodeOptions NodeOptions(const ros::RosConnection& ros, const RosInspectArgs& a) {
  ros::InspectionNodeOptions o;
  ros::RosTopics& t = o.topics;
  t.frames = ros.Param("frames_topic", t.frames);
  t.odometry = ros.Param("odometry_topic", t.odometry);
  t.dive = ros.Param("dive_topic", t.dive);
  o.navigation.source = ros::ParseNavigationSource(
      ros.Param("navigation_source", ros::ToString(o.navigation.source)), "~navigation_source");
  o.navigation.axes = ros::ParseNavigationAxes(
      ros.Param("navigation_axes", ros::ToString(o.navigation.axes)), "~navigation_axes");
  ros::RosFrames& f = o.frames;
  f.map = ros.Param("map_frame", f.map);
  f.odom = ros.Param("odom_frame", f.odom);
  f.base_link = ros.Param("base_frame", f.base_link);
  f.camera = ros.Param("camera_frame", f.camera);
  const std::string scanner_file = ros.Param("scanner", a.scanner_file);
  if (!a.camera.empty()) {
    CameraArgs camera;
    camera.camera = a.camera;
    camera.scene = a.scene;
    camera.scanner_file = scanner_file;
    o.camera = ros::CameraInput{MakeCameraSettings(camera), a.scene, scanner_file};
  } else if (!scanner_file.empty()) {
    mapping::DiveLogHeader header;
    header.scanner = scanner::LoadScanner(scanner_file);
    header.scan_pattern.kind = header.scanner.kind();
    o.header = header;
  }
  o.reference = LoadLiveReference(a.reference);
  o.description_wait_s = ros.Param("description_wait_s", o.description_wait_s);
  o.mount_wait_s = ros.Param("mount_wait_s", o.mount_wait_s);
  o.map_period_s = ros.Param("map_period_s", o.map_period_s);
  o.frame_queue = ros.Param("frame_queue", o.frame_queue);
  o.keep_images = ros.Param("images", o.keep_images);
  o.inspection.map_voxel_m = ros.Param("voxel_m", o.inspection.map_voxel_m);
  o.inspection.mapper.sweeps_per_submap =
      ros.Param("sweeps_per_submap", o.inspection.mapper.sweeps_per_submap);
  o.inspection.mapper.whole_solve_lag_s =
      ros.Param("whole_solve_lag_s", o.inspection.mapper.whole_solve_lag_s);
  o.inspection.mapper.spill_folder = TemporaryFolder();
  // On the vehicle every frame should reach SLAM (a skipped frame is a hole in the map), so the
  // live queue absorbs the mapper's pauses at submaps and solves: 1024 frames are 3 s at the
  // seed camera's 339 frames/s (and about 8 MB of peaks).
  o.inspection.live_queue_frames = ros.Param("live_queue", 1024);
  o.inspection.table_cache = TableCache();
  o.log = a.log;
  o.max_frames = a.frames;
  o.idle_stop_s = a.idle_stop_s;
  o.producer = std::string("uwscan ros inspect ") + UWSCAN_VERSION;
  return o;
}

// A camera topic silent this long is said so once, on its own line (a camera or driver that
// stopped while the vehicle goes on).
constexpr double kSilentFrames_s = 2.0;

void ReportSilence(const ros::InspectionNodeStatus& s, const std::string& topic, bool& reported) {
  if (s.frames_silent_s >= kSilentFrames_s && !reported) {
    std::fprintf(stderr,
                 "%sros inspect: no frame on %s for %.1f s (%lld navigation samples so far)\n",
                 isatty(2) ? "\n" : "", topic.c_str(), s.frames_silent_s,
                 static_cast<long long>(s.navigation_samples));
  } else if (s.frames_silent_s < kSilentFrames_s && reported) {
    std::fprintf(stderr, "%sros inspect: frames on %s again\n", isatty(2) ? "\n" : "",
                 topic.c_str());
  }
  reported = s.frames_silent_s >= kSilentFrames_s;
}

void PrintStatus(const ros::InspectionNodeStatus& s) {
  const mapping::InspectionStatistics& i = s.statistics;
  std::fprintf(stderr,
               "%sros inspect: %lld frames, logged %lld, mapped %lld, skipped %lld, waiting %lld, "
               "without navigation "
               "%lld; %d submaps%s%s",
               isatty(2) ? "\r" : "", static_cast<long long>(i.frames_received),
               static_cast<long long>(i.frames_logged), static_cast<long long>(i.frames_mapped),
               static_cast<long long>(i.frames_skipped), static_cast<long long>(i.frames_waiting),
               static_cast<long long>(i.frames_without_navigation), i.submaps,
               s.master_reachable ? "" : "; ROS master lost", isatty(2) ? "   " : "\n");
}

nlohmann::json MinutesJson(const std::vector<ros::MinuteLatency>& minutes) {
  nlohmann::json list = nlohmann::json::array();
  for (const ros::MinuteLatency& m : minutes)
    list.push_back({{"sweeps", m.count}, {"p95_s", m.p95_s}, {"max_s", m.max_s}});
  return list;
}

nlohmann::json SummaryJson(const ros::InspectionNodeSummary& s) {
  const mapping::InspectionStatistics& i = s.result.statistics;
  return {
      {"frames_received", i.frames_received},
      {"frames_logged", i.frames_logged},
      {"frames_mapped", i.frames_mapped},
      {"frames_skipped", i.frames_skipped},
      {"frames_without_navigation", i.frames_without_navigation},
      {"frames_out_of_order", i.frames_out_of_order},
      {"frames_undecodable", s.frames_undecodable},
      {"camera_lost_frames", s.camera_lost_frames},
      {"navigation_samples", s.navigation_samples},
      {"receive_span_s", s.receive_span_s},
      {"navigation_logged", i.log.navigation_written},
      {"sweeps_published", s.sweeps_published},
      {"maps_published", s.maps_published},
      {"maps_replaced", s.maps_replaced},
      {"submaps", i.submaps},
      {"map_points", s.result.map.size()},
      {"reregistrations", s.reregistrations},
      {"scanner_from_dive_description", s.described},
      {"mount", s.mount},
      {"time_origin_s", s.time_origin_s},
      {"receive_to_map_s",
       {{"median", i.receive_to_map.median_s}, {"p95", i.receive_to_map.p95_s}}},
      {"sweep_latency_s", {{"median", s.sweep_latency_median_s}, {"p95", s.sweep_latency_p95_s}}},
      {"sweep_latency_by_minute", MinutesJson(s.sweep_latency_by_minute)},
      {"stop_reason", s.stop_reason}};
}

void RunRosInspect(const RosInspectArgs& a) {
  if (!a.scene.empty() && a.camera.empty())
    throw Error("--scene: only with --camera (a simulated camera's scene)");
  if (!a.log.empty()) CheckNewLogPath(a.log, a.force, "--log");
  if (!a.map.empty()) CheckCloudOutputPath(a.map, "-o");
  if (!a.trajectory.empty()) CheckOutputPath(a.trajectory, "--trajectory");
  if (!a.json.empty()) CheckOutputPath(a.json, "--json");
  CheckRosArguments(a.ros_arguments);
  // Before ROS starts its threads; the whole-graph solves are beside the mapping unless
  // ~whole_solve_lag_s is 0, and one arena costs nothing measurable then. The map's publications
  // free large buffers all through the dive.
  UseOneMallocArena();
  MapLargeBlocksAlone();
  InstallStopHandlers();
  ros::RosConnection ros("uwscan_inspection", a.ros_arguments, a.master_wait_s);
  const ros::InspectionNodeOptions options = NodeOptions(ros, a);
  if (!a.log.empty()) RemoveLog(a.log);
  const std::string navigation =
      options.navigation.source == ros::NavigationSource::kTf
          ? options.topics.tf + " (" + options.frames.odom + " -> " + options.frames.base_link + ")"
          : options.topics.odometry;
  std::printf("ros inspect: frames %s %s, navigation on %s in %s axes; %s\n",
              options.camera ? "from the camera" : "on",
              options.camera ? a.camera.c_str() : options.topics.frames.c_str(), navigation.c_str(),
              options.navigation.axes == ros::NavigationAxes::kEnuFlu ? "ENU/FLU" : "NED/FRD",
              a.log.empty() ? "no log" : ("logging to " + a.log).c_str());
  std::fflush(stdout);
  bool silence_reported = false;
  const ros::InspectionNodeSummary s = ros::RunInspectionNode(
      ros, options, [] { return StopRequested(); },
      [&](const ros::InspectionNodeStatus& status) {
        PrintStatus(status);
        ReportSilence(status, options.topics.frames, silence_reported);
      });
  const mapping::InspectionStatistics& i = s.result.statistics;
  std::printf(
      "ros inspect: %lld frames received, %lld logged, %lld mapped, %lld skipped, %lld without "
      "navigation, "
      "%lld undecodable; %lld navigation samples; %lld sweeps and %lld maps published; %d submaps "
      "(%s)\n",
      static_cast<long long>(i.frames_received), static_cast<long long>(i.frames_logged),
      static_cast<long long>(i.frames_mapped), static_cast<long long>(i.frames_skipped),
      static_cast<long long>(i.frames_without_navigation),
      static_cast<long long>(s.frames_undecodable), static_cast<long long>(s.navigation_samples),
      static_cast<long long>(s.sweeps_published), static_cast<long long>(s.maps_published),
      i.submaps, s.stop_reason.c_str());
  if (i.frames_without_navigation > 0) {
    std::printf("ros inspect: %lld frames logged but not mapped: no navigation around their time\n",
                static_cast<long long>(i.frames_without_navigation));
  }
  std::printf("ros inspect: scanner from %s; camera mount from %s\n",
              s.described ? "the dive description" : "the scanner file", s.mount.c_str());
  if (!a.map.empty()) perception::WriteCloud(a.map, s.result.map, true);
  if (!a.trajectory.empty()) mapping::WriteTum(a.trajectory, s.result.slam);
  if (!a.json.empty()) WriteJsonFile(a.json, SummaryJson(s));
}

}  // namespace

void AddRosCommands(CLI::App& app) {
  CLI::App* ros = app.add_subcommand("ros", "uwscan on the vehicle: ROS 1 nodes");
  ros->require_subcommand(1);
  auto a = std::make_shared<RosInspectArgs>();
  CLI::App* cmd = ros->add_subcommand("inspect",
                                      "online inspection as a ROS 1 node: frames from an image "
                                      "topic and the vehicle's odometry, logged and "
                                      "mapped with loop closures; sweeps, map, paths, pose and the "
                                      "map -> odom correction published");
  cmd->footer(kParameterHelp);
  cmd->allow_extras();
  cmd->add_option(
         "--scanner", a->scanner_file,
         "scanner (calibration) file: of the camera (--camera), or when no dive description comes")
      ->check(CLI::ExistingFile);
  cmd->add_option("--camera", a->camera,
                  "read frames from this camera (IPv4 address, opened directly) instead of the "
                  "image topic; its clock "
                  "must be the navigation's (PTP)");
  cmd->add_option("--scene", a->scene,
                  "with --camera: a simulated camera's scene (its scanner and mount)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--log", a->log,
                  "dive log to create (.db): every frame and navigation sample, each committed");
  cmd->add_flag("--force", a->force, "replace an existing log at the --log path");
  cmd->add_option("-o,--map", a->map, "map to write at the end (.ply or .pcd)");
  cmd->add_option("--trajectory", a->trajectory,
                  "SLAM trajectory at the submaps' anchors to write at the end (TUM)");
  cmd->add_option("--json", a->json, "figures as JSON at the end");
  AddLiveReferenceOptions(*cmd, a->reference,
                          "the published map carries each point's deviation from it, field "
                          "\"deviation\" (metres), for RViz to colour by");
  cmd->add_option("--frames", a->frames, "stop after this many frames")->check(kPositiveNumber);
  cmd->add_option("--idle-stop-s", a->idle_stop_s,
                  "stop when frames stopped coming this long (replays)")
      ->check(kPositiveNumber);
  cmd->add_option("--master-wait-s", a->master_wait_s,
                  "how long to wait for the ROS master at start, s")
      ->capture_default_str()
      ->check(kPositiveNumber);
  cmd->callback([a, cmd] {
    a->ros_arguments = cmd->remaining();
    RunRosInspect(*a);
  });
  AddRosRecognizeCommand(*ros);
}

}  // namespace uwscan::app
