#pragma once

#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "mapping/change/live_deviation.hpp"
#include "perception/cloud/point_cloud.hpp"
#include "ros/bridge/ros_connection.hpp"
#include "ros/conversions/navigation_input.hpp"

namespace uwscan::ros {

// Publishes the map from a thread of its own. Turning a map into a message (its points into the
// navigation's axes, and with a reference each point's deviation from it) costs time in
// proportion to the map, which the mapping thread must spend on frames: it only hands the map
// over. The newest map wins: one handed over while another still waits replaces it.
class MapPublisher {
 public:
  // `map_id` is the map topic's publisher (RosConnection::Advertise). A failure while publishing
  // goes to `on_failure`, once; nothing is published after it.
  MapPublisher(RosConnection& ros, int map_id, NavigationAxes axes,
               std::shared_ptr<const mapping::LiveDeviation> reference,
               std::function<void(std::exception_ptr)> on_failure);
  ~MapPublisher();
  MapPublisher(const MapPublisher&) = delete;
  MapPublisher& operator=(const MapPublisher&) = delete;

  // Hands a map in uwscan's world frame over; returns at once.
  void Submit(perception::PointCloud map_W, Header header);
  // Publishes this map after the one in flight (a waiting one is dropped for it) and returns
  // once it is out: the last map of a dive. Rethrows a failure of the thread.
  void PublishLast(perception::PointCloud map_W, Header header);

  // A map already published (or replaced), to build the next one in: its storage, the map's
  // size, is then reused rather than asked for anew, and faulted in anew, for every map (the node
  // serves blocks that large from pages of their own, MapLargeBlocksAlone). Empty when none has
  // come back.
  perception::PointCloud TakeSpare();

  std::int64_t published() const;
  std::int64_t replaced() const;  // maps handed over but replaced by a newer one before their turn

 private:
  struct Pending {
    perception::PointCloud map_W;
    Header header;
  };
  void Run();
  void Publish(const Pending& p);

  RosConnection& ros_;
  int map_id_;
  NavigationAxes axes_;
  std::shared_ptr<const mapping::LiveDeviation> reference_;
  std::function<void(std::exception_ptr)> on_failure_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<Pending> pending_;
  perception::PointCloud spare_;
  bool busy_ = false, stopping_ = false;
  std::exception_ptr failure_;
  std::int64_t published_ = 0, replaced_ = 0;
  std::thread thread_;  // last: started once the rest is set
};

}  // namespace uwscan::ros
