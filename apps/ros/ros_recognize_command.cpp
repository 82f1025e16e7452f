#include "apps/ros/ros_recognize_command.hpp"

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli/json_output.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/output_path.hpp"
#include "apps/cli/stop_signal.hpp"
#include "apps/ros/ros_arguments.hpp"
#include "perception/recognition/object_database.hpp"
#include "ros/node/recognition_node.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::app {
namespace {

struct RosRecognizeArgs {
  std::string db;
  std::string json;
  std::int64_t sweeps = 0;
  double idle_stop_s = 0.0;
  double master_wait_s = 10.0;
  std::uint64_t seed = 1;
  int threads = 0;
  std::vector<std::string> ros_arguments;
};

const char* const kParameterHelp =
    "ROS parameters (private, ~name; or _name:=value here):\n"
    "  ~sweeps_topic   sweeps to search, sensor_msgs/PointCloud2 (sensor frame)  [/uwscan/sweep]\n"
    "  ~min_points     smaller sweeps are skipped                                 [200]\n"
    "Publishes: /uwscan/objects (visualization_msgs/MarkerArray: each model at its pose, a label "
    "with\n"
    "id and score), /uwscan/object_poses (geometry_msgs/PoseWithCovarianceStamped, one per "
    "object;\n"
    "covariance of the object's origin and orientation in the sweep's frame), /uwscan/grasps\n"
    "(geometry_msgs/PoseArray, every grasp frame of the sweep's objects). The newest sweep is "
    "searched\n"
    "whenever the last is done; the ones in between are skipped and counted.";

void RunRosRecognize(const RosRecognizeArgs& a) {
  if (!a.json.empty()) CheckOutputPath(a.json, "--json", {a.db});
  CheckRosArguments(a.ros_arguments);
  const perception::ObjectDatabase db = perception::ObjectDatabase::Load(a.db);
  InstallStopHandlers();
  ros::RosConnection ros("uwscan_recognition", a.ros_arguments, a.master_wait_s);
  ros::RecognitionNodeOptions options;
  options.sweeps_topic = ros.Param("sweeps_topic", options.sweeps_topic);
  options.min_points = ros.Param("min_points", options.min_points);
  options.recognition.seed = a.seed;
  options.recognition.threads = a.threads;
  options.max_sweeps = a.sweeps;
  options.idle_stop_s = a.idle_stop_s;
  std::printf("ros recognize: %zu objects from %s; sweeps on %s\n", db.objects.size(), a.db.c_str(),
              options.sweeps_topic.c_str());
  std::fflush(stdout);
  const ros::RecognitionNodeSummary s =
      ros::RunRecognitionNode(ros, db, options, [] { return StopRequested(); });
  std::printf("ros recognize: %lld sweeps received, %lld recognised, %lld skipped (%s)\n",
              static_cast<long long>(s.sweeps_received),
              static_cast<long long>(s.sweeps_recognised), static_cast<long long>(s.sweeps_skipped),
              s.stop_reason.c_str());
  nlohmann::json objects = nlohmann::json::object();
  for (const auto& [id, count] : s.objects) {
    std::printf("  %-14s recognised in %lld sweeps\n", id.c_str(), static_cast<long long>(count));
    objects[id] = count;
  }
  if (!a.json.empty()) {
    WriteJsonFile(a.json, {{"sweeps_received", s.sweeps_received},
                           {"sweeps_recognised", s.sweeps_recognised},
                           {"sweeps_skipped", s.sweeps_skipped},
                           {"objects", objects},
                           {"stop_reason", s.stop_reason}});
  }
}

}  // namespace

void AddRosRecognizeCommand(CLI::App& ros) {
  auto a = std::make_shared<RosRecognizeArgs>();
  CLI::App* cmd = ros.add_subcommand("recognize",
                                     "recognition as a ROS 1 node: the database's objects found in "
                                     "each published sweep; poses with "
                                     "covariance, grasp poses and markers published");
  cmd->footer(kParameterHelp);
  cmd->allow_extras();
  cmd->add_option("--db", a->db, "object database from `uwscan build-db`")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--json", a->json, "figures as JSON at the end: sweeps, objects recognised");
  cmd->add_option("--sweeps", a->sweeps, "stop after this many sweeps recognised")
      ->check(kPositiveNumber);
  cmd->add_option("--idle-stop-s", a->idle_stop_s,
                  "stop when no sweep came for this long (replays)")
      ->check(kPositiveNumber);
  cmd->add_option("--master-wait-s", a->master_wait_s,
                  "how long to wait for the ROS master at start, s")
      ->capture_default_str()
      ->check(kPositiveNumber);
  cmd->add_option("--seed", a->seed, "RANSAC and ESF seed")->capture_default_str();
  cmd->add_option("--threads", a->threads, "threads (0: all)")->check(kNonNegativeNumber);
  cmd->callback([a, cmd] {
    a->ros_arguments = cmd->remaining();
    RunRosRecognize(*a);
  });
}

}  // namespace uwscan::app
