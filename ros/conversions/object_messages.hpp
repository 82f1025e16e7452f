#pragma once

#include <string>
#include <vector>

#include "perception/recognition/object_database.hpp"
#include "perception/recognition/recognition_report.hpp"
#include "ros/bridge/messages.hpp"

// Recognised objects as standard ROS messages, the same for the recognition node and for a
// recognition report exported to a bag: each object's pose with its covariance
// (geometry_msgs/PoseWithCovarianceStamped), every grasp (geometry_msgs/PoseArray), and markers
// (visualization_msgs/MarkerArray: a delete-all, then per object its model's points at its pose
// and a label with its id and score).
namespace uwscan::ros {

// Model points drawn per object unless said otherwise: enough for the shape, few enough for RViz.
constexpr int kDefaultModelMarkerPoints = 1500;

struct ObjectMessages {
  std::vector<MarkerMessage> markers;
  std::vector<PoseMessage> poses;  // one per recognised object, in `objects`' order
  PoseArrayMessage grasps;
};

// Objects whose id is "unknown" are left out. `model_marker_points` (>= 1) model points are drawn
// per object, evenly strided. Throws uwscan::Error when the database lacks a recognised object.
ObjectMessages MakeObjectMessages(const std::vector<perception::ReportedObject>& objects,
                                  const perception::ObjectDatabase& db, const Header& header,
                                  int model_marker_points);

// Covariance of T_S_O in ROS's form (position of the object's origin, then rotation about the
// scan's axes) from recognition's (rotation w and translation v in the object frame, moving x
// to x + w x (x - c) + v, c the model's centroid).
Covariance6d ObjectPoseCovariance(const Eigen::Isometry3d& T_S_O,
                                  const Eigen::Vector3d& model_centroid_O,
                                  const Eigen::Matrix<double, 6, 6>& covariance);

}  // namespace uwscan::ros
