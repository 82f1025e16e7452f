#pragma once

// What the ROS inspection node publishes from its mapping thread (inspection_node.cpp): sweeps,
// paths, pose, TF and map. Included by inspection_node.cpp only.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "mapping/slam/live_map.hpp"
#include "mapping/slam/mapper.hpp"
#include "ros/node/inspection_node.hpp"
#include "ros/node/latency_by_minute.hpp"
#include "ros/node/map_publisher.hpp"
#include "ros/node/thread_share.hpp"

namespace uwscan::ros::inspection_detail {

using Clock = std::chrono::steady_clock;

inline double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

inline double UnixNow() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// ROS's covariance order (position, rotation) from uwscan's [rotation, position].
inline Covariance6d RosCovariance(const mapping::Matrix6d& c) {
  Covariance6d out;
  out << c.bottomRightCorner<3, 3>(), c.bottomLeftCorner<3, 3>(), c.topRightCorner<3, 3>(),
      c.topLeftCorner<3, 3>();
  return out;
}

// After a whole-graph solve the live map's settled part is merged anew this many submaps per map
// (LiveMap's rebuild_batch): a tenth of a second or so, where all of them at once took seconds
// late in a long dive, with the sweeps waiting behind.
constexpr int kLiveMapRebuildBatch = 400;

// Publishes what the mapper makes: sweeps, paths, pose, TF and map.
class Outlet {
 public:
  Outlet(RosConnection& ros, const InspectionNodeOptions& o, double time_origin_s,
         int frames_per_sweep, std::function<void(std::exception_ptr)> on_failure)
      : ros_(ros),
        options_(o),
        origin_s_(time_origin_s),
        frames_per_sweep_(frames_per_sweep),
        live_map_(o.inspection.map_voxel_m, /*settle_batch=*/100, kLiveMapRebuildBatch),
        map_share_(0.1, o.map_period_s) {
    const RosTopics& t = o.topics;
    sweep_id_ = ros.Advertise(t.sweeps, RosConnection::Kind::kCloud, false);
    map_ =
        std::make_unique<MapPublisher>(ros, ros.Advertise(t.map, RosConnection::Kind::kCloud, true),
                                       o.navigation.axes, o.reference, std::move(on_failure));
    slam_path_id_ = ros.Advertise(t.slam_path, RosConnection::Kind::kPath, true);
    navigation_path_id_ = ros.Advertise(t.navigation_path, RosConnection::Kind::kPath, true);
    pose_id_ = ros.Advertise(t.pose, RosConnection::Kind::kPose, true);
    tf_id_ = ros.Advertise(t.tf, RosConnection::Kind::kTransforms, false);
  }

  // Mapping thread: a frame placed. A sweep is published with its last frame (the scan
  // pattern's frames per sweep), or when the next one starts if frames of it were lost; in the
  // camera frame at its last frame (each point placed with the navigation at its own frame).
  void OnMapped(const mapping::MappedFrame& f) {
    if (sweep_ && f.sweep != *sweep_ && !sweep_points_W_.empty()) PublishSweep();
    if (!sweep_ || f.sweep != *sweep_) frames_in_sweep_ = 0;
    sweep_ = f.sweep;
    sweep_time_s_ = f.time_s;
    sweep_received_s_ = f.receive_time_s;
    T_W_C_last_ = f.T_W_C;
    sweep_points_W_.insert(sweep_points_W_.end(), f.points_W.begin(), f.points_W.end());
    if (++frames_in_sweep_ == frames_per_sweep_) PublishSweep();
  }

  // Mapping thread: a submap closed.
  void OnSubmapClosed(const mapping::Mapper& m) {
    const int last = m.submap_count() - 1;
    const double time_s = m.submap(last).anchor_time_s;
    const mapping::TimedPose slam{time_s, m.pose(last)},
        navigation{time_s, m.submap(last).T_W_V_nav};
    PublishCorrection(slam, navigation);
    if (pose_share_.Due(Now())) {
      const double start_s = Now();
      PublishPose(m, slam);
      pose_share_.Done(start_s, Now());
    }
    if (map_share_.Due(Now())) {
      const double start_s = Now();
      PublishPaths(m);
      perception::PointCloud map_W = map_->TakeSpare();
      live_map_.Build(m, map_W);
      map_->Submit(std::move(map_W), Stamp(time_s, options_.frames.map));
      map_share_.Done(start_s, Now());
    }
  }

  // After the inspection finished: the last sweep (if frames of it were lost), the final map
  // and paths.
  void Finish(const mapping::InspectionResult& r) {
    if (!sweep_points_W_.empty()) PublishSweep();
    if (r.slam.empty()) return;
    PublishPaths(r.slam, r.navigation);
    PublishCorrection(r.slam.back(), r.navigation.back());
    map_->PublishLast(r.map, Stamp(r.slam.back().time_s, options_.frames.map));
  }

  std::int64_t sweeps() const { return sweeps_; }
  std::int64_t maps_published() const { return map_->published(); }
  std::int64_t maps_replaced() const { return map_->replaced(); }
  // Median and 95th percentile of the sweeps' latencies; call once the mapping thread ended.
  std::pair<double, double> SweepLatency() const {
    if (sweep_latencies_s_.empty()) return {0.0, 0.0};
    std::vector<double> sorted = sweep_latencies_s_;
    std::sort(sorted.begin(), sorted.end());
    return {sorted[sorted.size() / 2],
            sorted[std::min(sorted.size() - 1, sorted.size() * 95 / 100)]};
  }
  // The same by minute of publishing; call once the mapping thread ended.
  std::vector<MinuteLatency> SweepLatencyByMinute() const { return latency_by_minute_.Minutes(); }

 private:
  double Now() const { return SecondsSince(start_); }  // steady
  Header Stamp(double time_s, const std::string& frame) const {
    return {origin_s_ + time_s, frame};
  }
  NavigationAxes axes() const { return options_.navigation.axes; }
  // A vehicle pose in the navigation's own axes, as the vehicle's software reads it.
  Eigen::Isometry3d Out(const Eigen::Isometry3d& T_W_V) const {
    return VehiclePoseInNavigationAxes(T_W_V, axes());
  }

  void PublishSweep() {
    CloudMessage c;
    c.header = Stamp(sweep_time_s_, options_.frames.camera);
    const Eigen::Isometry3d T_C_W = T_W_C_last_.inverse();
    c.points.reserve(sweep_points_W_.size());
    for (const Eigen::Vector3d& p : sweep_points_W_) c.points.push_back((T_C_W * p).cast<float>());
    ros_.Publish(sweep_id_, c);
    const double latency_s = UnixNow() - sweep_received_s_;
    sweep_latencies_s_.push_back(latency_s);
    // By the steady clock: a system clock set mid-dive (NTP) would move the minutes.
    latency_by_minute_.Add(SecondsSince(start_), latency_s);
    sweep_points_W_.clear();
    ++sweeps_;
  }

  // Both paths in the map frame (uwscan's world: the navigation's, corrected).
  void PublishPaths(const std::vector<mapping::TimedPose>& slam,
                    const std::vector<mapping::TimedPose>& navigation) {
    ros_.Publish(slam_path_id_, Path(slam));
    ros_.Publish(navigation_path_id_, Path(navigation));
  }
  void PublishPaths(const mapping::Mapper& m) {
    std::vector<mapping::TimedPose> slam, navigation;
    for (int i = 0; i < m.submap_count(); ++i) {
      slam.push_back({m.submap(i).anchor_time_s, m.pose(i)});
      navigation.push_back({m.submap(i).anchor_time_s, m.submap(i).T_W_V_nav});
    }
    PublishPaths(slam, navigation);
  }

  // The correction at the newest anchor as map -> odom.
  void PublishCorrection(const mapping::TimedPose& slam, const mapping::TimedPose& navigation) {
    const RosFrames& f = options_.frames;
    const Eigen::Isometry3d T_map_odom = Out(slam.T_W_V) * Out(navigation.T_W_V).inverse();
    ros_.Publish(tf_id_,
                 std::vector<TransformMessage>{{Stamp(slam.time_s, f.map), f.odom, T_map_odom}});
  }

  void PublishPose(const mapping::Mapper& m, const mapping::TimedPose& newest) {
    const std::optional<mapping::Mapper::SubmapCovariances> c = m.Covariances();
    if (!c) return;
    ros_.Publish(pose_id_, PoseMessage{Stamp(newest.time_s, options_.frames.map), Out(newest.T_W_V),
                                       WorldCovarianceInNavigationAxes(
                                           RosCovariance(c->anchors.back()), axes())});
  }

  PathMessage Path(const std::vector<mapping::TimedPose>& poses) const {
    PathMessage p;
    p.header = Stamp(poses.back().time_s, options_.frames.map);
    for (const mapping::TimedPose& pose : poses) {
      p.stamps_s.push_back(origin_s_ + pose.time_s);
      p.poses.push_back(Out(pose.T_W_V));
    }
    return p;
  }

  RosConnection& ros_;
  const InspectionNodeOptions& options_;
  double origin_s_;
  int frames_per_sweep_;
  int frames_in_sweep_ = 0;
  int sweep_id_ = 0, slam_path_id_ = 0, navigation_path_id_ = 0, pose_id_ = 0, tf_id_ = 0;
  std::optional<int> sweep_;
  double sweep_time_s_ = 0.0;
  double sweep_received_s_ = 0.0;
  std::vector<double> sweep_latencies_s_;  // one per sweep: a dive of hours holds ~10^5
  LatencyByMinute latency_by_minute_;
  Clock::time_point start_ = Clock::now();
  Eigen::Isometry3d T_W_C_last_ = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector3d> sweep_points_W_;
  mapping::LiveMap live_map_;
  // Both grow with the dive; each takes a bounded share of the mapping thread (ThreadShare). The
  // newest anchor's marginal covariance comes from the whole graph's information (its selected
  // inverse alone: 1.6 s at the end of a 30-minute dive, bench/slam/RESULTS.md): on short dives
  // after every submap, late in long ones every half minute or so. The paths and the map hold the
  // whole dive, and the live map merges again for each map what the solves moved since the last
  // one (up to every submap a loop may free): at most every map_period_s.
  ThreadShare pose_share_{0.05, 0.0};
  ThreadShare map_share_;
  std::atomic<std::int64_t> sweeps_{0};
  std::unique_ptr<MapPublisher> map_;
};

}  // namespace uwscan::ros::inspection_detail
