#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "perception/recognition/object_database.hpp"
#include "perception/recognition/object_recognizer.hpp"
#include "ros/bridge/ros_connection.hpp"
#include "ros/conversions/object_messages.hpp"
#include "ros/conversions/ros_names.hpp"

// Recognition on the vehicle (`uwscan ros recognize`): the objects of a database found in the
// sweeps `uwscan ros inspect` publishes (each in the camera frame, the sensor at the origin, as
// recognition expects), published with standard messages only: each object's pose with its
// covariance, its grasp poses, and markers (the model at its pose, a label with id and score).
// The newest sweep is recognised whenever the last one is done; the ones in between are
// counted as skipped.
namespace uwscan::ros {

struct RecognitionNodeOptions {
  std::string sweeps_topic = RosTopics{}.sweeps;       // sensor_msgs/PointCloud2, in
  std::string objects_topic = RosTopics{}.objects;     // visualization_msgs/MarkerArray
  std::string poses_topic = RosTopics{}.object_poses;  // one PoseWithCovarianceStamped per object
  std::string grasps_topic =
      RosTopics{}.grasps;  // geometry_msgs/PoseArray, every grasp of the sweep
  int min_points = 200;    // sweeps with fewer points are skipped, >= 1
  int model_marker_points = kDefaultModelMarkerPoints;  // per object (evenly strided), >= 1
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

// Runs until `stop_requested`, roscpp shuts down or a limit is reached.
RecognitionNodeSummary RunRecognitionNode(RosConnection& ros, const perception::ObjectDatabase& db,
                                          const RecognitionNodeOptions& options,
                                          const std::function<bool()>& stop_requested);

}  // namespace uwscan::ros
