#pragma once

#include <exception>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "ros/bridge/messages.hpp"

// One process's connection to a ROS 1 master through roscpp, in uwscan's message types
// (messages.hpp). C++17, no ROS include.
//
// roscpp does not re-register a node with a master that was restarted: KeepRegistered() checks
// the master and, when it is back after being lost, advertises and subscribes everything again
// (peer-to-peer connections to publishers survive a master's death, so frames keep flowing
// meanwhile from publishers already connected).
namespace uwscan::ros {

class RosConnection {
 public:
  // Starts roscpp as node `name` (command-line remappings "from:=to" in `arguments`), without
  // its SIGINT handler (the caller stops on its own signals). Throws uwscan::Error when the
  // master (ROS_MASTER_URI) does not answer within `master_wait_s`.
  RosConnection(const std::string& name, const std::vector<std::string>& arguments,
                double master_wait_s);
  ~RosConnection();  // shuts roscpp down
  RosConnection(const RosConnection&) = delete;
  RosConnection& operator=(const RosConnection&) = delete;

  // The node's private parameters (~name) with their defaults. Throws uwscan::Error naming the
  // parameter when it exists with another type.
  std::string Param(const std::string& name, const std::string& fallback) const;
  double Param(const std::string& name, double fallback) const;
  int Param(const std::string& name, int fallback) const;
  bool Param(const std::string& name, bool fallback) const;

  // Callbacks run on the connection's spinner threads (Start), one message at a time per
  // topic, in arrival order. `queue`: messages roscpp holds while a callback runs. A message
  // that does not convert (a NaN pose, a cloud without x) goes to the error handler instead,
  // as a uwscan::Error naming the topic; without a handler it is dropped.
  void SetErrorHandler(std::function<void(std::exception_ptr)> handler);
  void SubscribeImages(const std::string& topic, int queue,
                       std::function<void(ImageMessage&&)> callback);
  void SubscribeOdometry(const std::string& topic, int queue,
                         std::function<void(OdometryMessage&&)> callback);
  void SubscribeText(const std::string& topic, std::function<void(StringMessage&&)> callback);
  void SubscribeClouds(const std::string& topic, int queue,
                       std::function<void(CloudMessage&&)> callback);
  void SubscribeTransforms(const std::string& topic, int queue,
                           std::function<void(std::vector<TransformMessage>&&)> callback);

  // Ends every subscription; when it returns, no callback runs or will run (a callback in
  // progress is waited for).
  void Unsubscribe();

  // Publishers, by the id Advertise returns; Publish is thread-safe.
  enum class Kind { kCloud, kPath, kPose, kPoseArray, kMarkers, kTransforms };
  int Advertise(const std::string& topic, Kind kind, bool latched);
  void Publish(int id, const CloudMessage& message);
  void Publish(int id, const PathMessage& message);
  void Publish(int id, const PoseMessage& message);
  void Publish(int id, const PoseArrayMessage& message);
  void Publish(int id, const std::vector<MarkerMessage>& markers);
  void Publish(int id, const std::vector<TransformMessage>& transforms);

  // Starts `threads` spinner threads (callbacks of different topics run at once).
  void Start(int threads);
  // True while roscpp runs (false after a shutdown request from ROS, e.g. rosnode kill).
  bool Ok() const;
  // Whether the master answers now; after it was lost and is back, everything is registered
  // again. Returns true when the master answers. Call it about once a second.
  bool KeepRegistered();
  // Times the node registered again with a restarted master.
  int reregistrations() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace uwscan::ros
