#include "ros/node/recognition_node.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <optional>
#include <thread>

#include "perception/recognition/object_pose_search.hpp"
#include "ros/conversions/object_messages.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::ros {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// The newest sweep, handed from roscpp's thread to the recognising one.
class SweepSlot {
 public:
  void Put(CloudMessage&& sweep) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (sweep_) ++replaced_;
    sweep_ = std::move(sweep);
    ++received_;
    last_ = Clock::now();
  }
  std::optional<CloudMessage> Take() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::optional<CloudMessage> out = std::move(sweep_);
    sweep_.reset();
    return out;
  }
  std::int64_t received() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return received_;
  }
  std::int64_t replaced() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return replaced_;
  }
  // Since the last sweep came (or since the node started, before the first).
  double idle_s() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return SecondsSince(last_);
  }

 private:
  mutable std::mutex mutex_;
  std::optional<CloudMessage> sweep_;
  std::int64_t received_ = 0, replaced_ = 0;
  Clock::time_point last_ = Clock::now();
};

perception::PointCloud ToCloud(const CloudMessage& sweep) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(sweep.points.size());
  for (const Eigen::Vector3f& p : sweep.points) points.push_back(p.cast<double>());
  return perception::MakeCloud(points);
}

struct Publishers {
  int objects = 0, poses = 0, grasps = 0;
};

// Recognition's objects as the report's, which MakeObjectMessages takes.
std::vector<perception::ReportedObject> Reported(const perception::RecognitionResult& result) {
  std::vector<perception::ReportedObject> objects;
  for (const perception::RecognizedObject& o : result.objects) {
    perception::ReportedObject r;
    r.id = o.object_id;
    r.score = o.score;
    r.T_S_O = o.T_S_O;
    r.covariance = o.covariance;
    r.grasps_S = o.grasps_S;
    r.centroid_S = o.centroid_S;
    objects.push_back(std::move(r));
  }
  return objects;
}

void Publish(RosConnection& ros, const Publishers& p, const perception::ObjectDatabase& db,
             const perception::RecognitionResult& result, const Header& header,
             const RecognitionNodeOptions& o, RecognitionNodeSummary& summary) {
  const std::vector<perception::ReportedObject> objects = Reported(result);
  const ObjectMessages messages = MakeObjectMessages(objects, db, header, o.model_marker_points);
  for (const perception::ReportedObject& object : objects) {
    if (object.recognised()) ++summary.objects[object.id];
  }
  for (const PoseMessage& pose : messages.poses) ros.Publish(p.poses, pose);
  ros.Publish(p.objects, messages.markers);
  ros.Publish(p.grasps, messages.grasps);
}

std::string StopReason(const RecognitionNodeOptions& o, RosConnection& ros, const SweepSlot& slot,
                       const RecognitionNodeSummary& s,
                       const std::function<bool()>& stop_requested) {
  if (stop_requested()) return "stop requested";
  if (!ros.Ok()) return "ROS shut the node down";
  if (o.max_sweeps > 0 && s.sweeps_recognised >= o.max_sweeps)
    return std::to_string(o.max_sweeps) + " sweeps recognised";
  if (o.idle_stop_s > 0.0 && slot.idle_s() >= o.idle_stop_s)
    return "no sweep for " + std::to_string(o.idle_stop_s) + " s";
  return "";
}

}  // namespace

void RecognitionNodeOptions::Check() const {
  const OptionChecks check("RecognitionNodeOptions");
  check.AtLeast("min_points", min_points, 1);
  check.AtLeast("model_marker_points", model_marker_points, 1);
  check.AtLeast("max_sweeps", max_sweeps, 0);
  check.AtLeast("idle_stop_s", idle_stop_s, 0.0, "s");
}

RecognitionNodeSummary RunRecognitionNode(RosConnection& ros, const perception::ObjectDatabase& db,
                                          const RecognitionNodeOptions& o,
                                          const std::function<bool()>& stop_requested) {
  o.Check();
  Publishers publishers;
  publishers.objects = ros.Advertise(o.objects_topic, RosConnection::Kind::kMarkers, true);
  publishers.poses = ros.Advertise(o.poses_topic, RosConnection::Kind::kPose, false);
  publishers.grasps = ros.Advertise(o.grasps_topic, RosConnection::Kind::kPoseArray, true);
  SweepSlot slot;
  ros.SubscribeClouds(o.sweeps_topic, 4, [&slot](CloudMessage&& m) { slot.Put(std::move(m)); });
  ros.Start(1);
  perception::RecognitionCache cache(db);
  RecognitionNodeSummary summary;
  while ((summary.stop_reason = StopReason(o, ros, slot, summary, stop_requested)).empty()) {
    std::optional<CloudMessage> sweep = slot.Take();
    if (!sweep) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      continue;
    }
    if (sweep->points.size() < static_cast<std::size_t>(o.min_points)) {
      ++summary.sweeps_skipped;
      continue;
    }
    const perception::RecognitionResult result =
        perception::RecognizeObjects(ToCloud(*sweep), db, cache, o.recognition);
    Publish(ros, publishers, db, result, sweep->header, o, summary);
    ++summary.sweeps_recognised;
  }
  ros.Unsubscribe();
  summary.sweeps_received = slot.received();
  summary.sweeps_skipped += slot.replaced();
  return summary;
}

}  // namespace uwscan::ros
