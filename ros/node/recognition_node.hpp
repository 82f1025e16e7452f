#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "perception/recognition/object_database.hpp"
#include "perception/recognition/object_recognizer.hpp"
#include "ros/bridge/ros_connection.hpp"

// Recognition on the vehicle (`uwscan ros recognize`): the objects of a database found in the
// sweeps `uwscan ros inspect` publishes (each in the camera frame, the sensor at the origin, as
// recognition expects), published with standard messages only: each object's pose with its
// covariance, its grasp poses, and markers (the model at its pose, a label with id and score).
// The newest sweep is recognised whenever the last one is done; the ones in between are
// counted as skipped.
namespace uwscan::ros {

struct RecognitionNodeOptions {
  std::string sweeps_topic = "/uwscan/sweep";     // sensor_msgs/PointCloud2, in
  std::string objects_topic = "/uwscan/objects";  // visualization_msgs/MarkerArray
  std::string poses_topic =
      "/uwscan/object_poses";  // geometry_msgs/PoseWithCovarianceStamped, one per object
  std::string grasps_topic = "/uwscan/grasps";  // geometry_msgs/PoseArray, every grasp of the sweep
  int min_points = 200;                         // sweeps with fewer points are skipped, >= 1
  int model_marker_points = 1500;  // model points drawn per object (evenly strided), >= 1
  perception::RecognitionOptions recognition;
  // Stop after this many sweeps recognised (0: no limit), or once no sweep came for idle_stop_s
  // (since the last one, or since the start before the first; 0: never).
  std::int64_t max_sweeps = 0;
  double idle_stop_s = 0.0;
  void Check() const;  // throws uwscan::Error naming the field
};

struct RecognitionNodeSummary {
  std::int64_t sweeps_received = 0;
  std::int64_t sweeps_recognised = 0;
  std::int64_t sweeps_skipped =
      0;  // replaced by a newer one while recognition was busy, or too small
  std::map<std::string, std::int64_t> objects;  // times each object id was recognised
  std::string stop_reason;
};

// Covariance of T_S_O in ROS's form (position of the object's origin, then rotation about the
// scan's axes) from recognition's (rotation w and translation v in the object frame, moving x
// to x + w x (x - c) + v, c the model's centroid).
Covariance6d ObjectPoseCovariance(const Eigen::Isometry3d& T_S_O,
                                  const Eigen::Vector3d& model_centroid_O,
                                  const Eigen::Matrix<double, 6, 6>& covariance);

// Runs until `stop_requested`, roscpp shuts down or a limit is reached.
RecognitionNodeSummary RunRecognitionNode(RosConnection& ros, const perception::ObjectDatabase& db,
                                          const RecognitionNodeOptions& options,
                                          const std::function<bool()>& stop_requested);

}  // namespace uwscan::ros
