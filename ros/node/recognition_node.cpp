#include "ros/node/recognition_node.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <optional>
#include <thread>

#include "perception/recognition/object_pose_search.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& c) {
  Eigen::Matrix3d m;
  m << 0.0, -c.z(), c.y(), c.z(), 0.0, -c.x(), -c.y(), c.x(), 0.0;
  return m;
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

// A colour per object id, stable from run to run.
Eigen::Vector4f Colour(const std::string& id) {
  std::uint32_t h = 2166136261u;
  for (char c : id) h = (h ^ static_cast<std::uint8_t>(c)) * 16777619u;
  return {0.3F + 0.7F * static_cast<float>(h & 0xFF) / 255.0F,
          0.3F + 0.7F * static_cast<float>((h >> 8) & 0xFF) / 255.0F,
          0.3F + 0.7F * static_cast<float>((h >> 16) & 0xFF) / 255.0F, 1.0F};
}

// The model at its pose and a label above it.
void AddMarkers(const perception::RecognizedObject& o, const perception::ObjectModel& model, int id,
                const Header& header, int max_points, std::vector<MarkerMessage>& markers) {
  MarkerMessage points;
  points.header = header;
  points.ns = "uwscan_models";
  points.id = id;
  points.kind = MarkerMessage::Kind::kPoints;
  points.pose = o.T_S_O;
  points.rgba = Colour(o.object_id);
  const std::size_t stride =
      std::max<std::size_t>(1, model.model.size() / static_cast<std::size_t>(max_points));
  for (std::size_t i = 0; i < model.model.size(); i += stride)
    points.points.push_back(model.model.Point(i).cast<float>());
  markers.push_back(points);
  MarkerMessage label;
  label.header = header;
  label.ns = "uwscan_labels";
  label.id = id;
  label.kind = MarkerMessage::Kind::kText;
  label.pose = o.T_S_O;
  label.pose.translation() -=
      Eigen::Vector3d(0.0, 0.6 * model.diameter_m, 0.0);  // above it (y down)
  char text[96];
  std::snprintf(text, sizeof(text), "%s %.2f", o.object_id.c_str(), o.score);
  label.text = text;
  label.scale_m = 0.05;
  markers.push_back(label);
}

const perception::ObjectModel* FindModel(const perception::ObjectDatabase& db,
                                         const std::string& id) {
  for (const perception::ObjectModel& m : db.objects) {
    if (m.id == id) return &m;
  }
  return nullptr;
}

struct Publishers {
  int objects = 0, poses = 0, grasps = 0;
};

void Publish(RosConnection& ros, const Publishers& p, const perception::ObjectDatabase& db,
             const perception::RecognitionResult& result, const Header& header,
             const RecognitionNodeOptions& o, RecognitionNodeSummary& summary) {
  std::vector<MarkerMessage> markers;
  MarkerMessage clear;
  clear.header = header;
  clear.kind = MarkerMessage::Kind::kDeleteAll;
  markers.push_back(clear);
  PoseArrayMessage grasps;
  grasps.header = header;
  int id = 0;
  for (const perception::RecognizedObject& object : result.objects) {
    const perception::ObjectModel* model = FindModel(db, object.object_id);
    if (model == nullptr) continue;  // "unknown"
    ++summary.objects[object.object_id];
    AddMarkers(object, *model, id++, header, o.model_marker_points, markers);
    ros.Publish(p.poses,
                PoseMessage{header, object.T_S_O,
                            ObjectPoseCovariance(object.T_S_O, perception::Centroid(model->model),
                                                 object.covariance)});
    for (const auto& [name, T_S_G] : object.grasps_S) grasps.poses.push_back(T_S_G);
  }
  ros.Publish(p.objects, markers);
  ros.Publish(p.grasps, grasps);
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
  const auto fail = [](const std::string& field, const std::string& expected) {
    throw Error("RecognitionNodeOptions." + field + ": expected " + expected);
  };
  if (min_points < 1) fail("min_points", ">= 1");
  if (model_marker_points < 1) fail("model_marker_points", ">= 1");
  if (max_sweeps < 0) fail("max_sweeps", ">= 0");
  if (!(idle_stop_s >= 0.0)) fail("idle_stop_s", ">= 0 s");
}

Covariance6d ObjectPoseCovariance(const Eigen::Isometry3d& T_S_O, const Eigen::Vector3d& c,
                                  const Eigen::Matrix<double, 6, 6>& covariance) {
  // The object's origin moves by R (v + c x w), its orientation by R w about the scan's axes.
  const Eigen::Matrix3d R = T_S_O.rotation();
  Eigen::Matrix<double, 6, 6> J = Eigen::Matrix<double, 6, 6>::Zero();
  J.topLeftCorner<3, 3>() = R * Skew(c);
  J.topRightCorner<3, 3>() = R;
  J.bottomLeftCorner<3, 3>() = R;
  return J * covariance * J.transpose();
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
