#include "apps/ros/bag_commands.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli/output_path.hpp"
#include "ros/bag/bag_export.hpp"
#include "ros/bag/bag_import.hpp"
#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::app {
namespace {

struct ImportArgs {
  std::string bag;
  std::string log;
  std::string scanner_file;
  ros::RosTopics topics;
  ros::RosFrames frames;
  std::string navigation_source = "odometry";
  std::string navigation_axes = "ned";
  bool images = false;
};

struct ExportArgs {
  std::vector<std::string> inputs;
  std::string bag;
  ros::RosTopics topics;
  ros::RosFrames frames;
};

void RunImport(const ImportArgs& a) {
  CheckOutputPath(a.log, "-o", {a.bag});
  if (std::filesystem::exists(a.log))
    throw Error("-o " + a.log + ": exists (a dive log is never overwritten)");
  ros::BagImportOptions options;
  options.topics = a.topics;
  options.frames = a.frames;
  options.navigation.source = ros::ParseNavigationSource(a.navigation_source, "--navigation");
  options.navigation.axes = ros::ParseNavigationAxes(a.navigation_axes, "--navigation-axes");
  options.keep_images = a.images;
  options.producer = std::string("uwscan bag import ") + UWSCAN_VERSION + " (" +
                     std::filesystem::path(a.bag).filename().string() + ")";
  if (!a.scanner_file.empty()) {
    mapping::DiveLogHeader header;
    header.scanner = scanner::LoadScanner(a.scanner_file);
    header.scan_pattern.kind = header.scanner.kind();
    options.header = header;
  }
  const ros::BagImportSummary s = ros::ImportBag(a.bag, a.log, options);
  std::printf("bag import: %lld frames, %lld navigation samples -> %s\n",
              static_cast<long long>(s.frames), static_cast<long long>(s.navigation),
              a.log.c_str());
  std::printf("bag import: scanner from %s; camera mount from %s\n",
              s.described ? ("the bag's dive description (" + a.topics.dive + ")").c_str()
                          : ("--scanner " + a.scanner_file).c_str(),
              s.mount.c_str());
  if (s.time_origin_s != 0.0)
    std::printf("bag import: log time 0 is ROS time %.0f s\n", s.time_origin_s);
  if (s.undecodable > 0) {
    std::printf(
        "bag import: %lld frames left out: their metadata row does not decode (damaged payload)\n",
        static_cast<long long>(s.undecodable));
  }
}

void RunExport(const ExportArgs& a) {
  const std::vector<std::filesystem::path> inputs(a.inputs.begin(), a.inputs.end());
  CheckOutputPath(a.bag, "-o", inputs);
  if (std::filesystem::exists(a.bag))
    throw Error("-o " + a.bag + ": exists (a bag is never overwritten)");
  ros::BagExportOptions options;
  options.topics = a.topics;
  options.frames = a.frames;
  options.producer = std::string("uwscan bag export ") + UWSCAN_VERSION;
  const ros::BagExportSummary s = ros::ExportToBag(inputs, a.bag, options);
  if (s.frames > 0) {
    std::printf(
        "bag export: %lld frames (%lld as images, the rest as %d-row profiles) on %s, %lld "
        "navigation "
        "samples on %s and %s\n",
        static_cast<long long>(s.frames), static_cast<long long>(s.images), s.layout.peak_rows,
        a.topics.frames.c_str(), static_cast<long long>(s.navigation), a.topics.odometry.c_str(),
        a.topics.tf.c_str());
  }
  if (s.anchors > 0) {
    std::printf(
        "bag export: a map of %lld points on %s; paths, poses and map -> odom at %lld anchors\n",
        static_cast<long long>(s.map_points), a.topics.map.c_str(),
        static_cast<long long>(s.anchors));
  }
  if (s.scan_points > 0) {
    std::printf(
        "bag export: a scan of %lld points on %s; %lld objects on %s, %s and %lld grasps on %s\n",
        static_cast<long long>(s.scan_points), a.topics.sweeps.c_str(),
        static_cast<long long>(s.objects), a.topics.objects.c_str(), a.topics.object_poses.c_str(),
        static_cast<long long>(s.grasps), a.topics.grasps.c_str());
  }
  std::printf("bag export: written to %s\n", a.bag.c_str());
  if (s.time_origin_s != 0.0)
    std::printf("bag export: log time 0 is ROS time %.0f s\n", s.time_origin_s);
}

void AddTopicOptions(CLI::App& cmd, ros::RosTopics& t) {
  cmd.add_option("--frames-topic", t.frames, "camera frames (sensor_msgs/Image, uwscan's payload)")
      ->capture_default_str();
  cmd.add_option("--odometry-topic", t.odometry, "the vehicle's navigation (nav_msgs/Odometry)")
      ->capture_default_str();
  cmd.add_option("--dive-topic", t.dive,
                 "the dive description: scanner, scan pattern (std_msgs/String)")
      ->capture_default_str();
}

}  // namespace

void AddBagCommands(CLI::App& app) {
  CLI::App* bag = app.add_subcommand(
      "bag", "ROS 1 bags: import a vehicle's bag as a dive log, export a log as a bag");
  bag->require_subcommand(1);

  auto in = std::make_shared<ImportArgs>();
  CLI::App* import = bag->add_subcommand(
      "import",
      "a ROS 1 bag (camera frames + odometry) -> a dive log that map, reconstruct and view take");
  import->footer(
      "Frames: sensor_msgs/Image carrying the camera's payload (profile: mono16, one column per "
      "image line,\n"
      "peak rows + metadata row; image: mono8/mono16 with the metadata row below), time = the "
      "message's stamp.\n"
      "Navigation: nav_msgs/Odometry, or /tf with --navigation tf (T_odom_base_link; NED world,\n"
      "forward-right-down vehicle, or with --navigation-axes enu ENU, forward-left-up).\n"
      "Camera mount: /tf_static from the odometry's child frame to the images' frame (else "
      "identity).\n"
      "Scanner: the bag's dive description (bags uwscan wrote), else --scanner.");
  import->add_option("bag", in->bag, "the bag (.bag)")->required()->check(CLI::ExistingFile);
  import->add_option("-o,--output", in->log, "dive log to create (.db)")->required();
  import
      ->add_option("--scanner", in->scanner_file,
                   "scanner (calibration) file, for a bag without a dive description")
      ->check(CLI::ExistingFile);
  import->add_flag("--images", in->images,
                   "image-mode frames: keep the images in the log as well as the peaks");
  AddTopicOptions(*import, in->topics);
  import
      ->add_option("--navigation", in->navigation_source,
                   "odometry (the odometry topic) or tf (--odom-frame -> --base-frame on /tf)")
      ->check(CLI::IsMember({"odometry", "tf"}))
      ->capture_default_str();
  import
      ->add_option("--navigation-axes", in->navigation_axes,
                   "ned (NED world, forward-right-down vehicle) or enu (ENU world, "
                   "forward-left-up vehicle: REP 103's default); the mount is read in them too")
      ->check(CLI::IsMember({"ned", "enu"}))
      ->capture_default_str();
  import
      ->add_option("--odom-frame", in->frames.odom,
                   "the navigation's world frame (--navigation tf)")
      ->capture_default_str();
  import->add_option("--base-frame", in->frames.base_link, "the vehicle's frame (--navigation tf)")
      ->capture_default_str();
  import->callback([in] { RunImport(*in);
});

auto out = std::make_shared<ExportArgs>();
CLI::App* exp =
    bag->add_subcommand("export",
                        "dive logs, map and recognition reports -> a ROS 1 bag for rosbag play "
                        "and RViz: a log's frames, odometry, TF and dive description; a map "
                        "report's map, paths, poses and map -> odom; a recognition report's "
                        "scan, object poses, grasps and markers");
exp->add_option(
       "inputs", out->inputs,
       "dive logs (.db), map reports (map --json) and recognition reports (recognize --json)")
    ->required()
    ->check(CLI::ExistingFile);
exp->add_option("-o,--output", out->bag, "bag to create (.bag)")->required();
AddTopicOptions(*exp, out->topics);
exp->add_option("--odom-frame", out->frames.odom, "the navigation's world frame")
    ->capture_default_str();
exp->add_option("--base-frame", out->frames.base_link, "the vehicle's frame")
    ->capture_default_str();
exp->add_option("--camera-frame", out->frames.camera, "the camera's frame")->capture_default_str();
exp->callback([out] { RunExport(*out); });
}  // namespace uwscan::app

}  // namespace uwscan::app
