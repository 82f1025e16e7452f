#pragma once

// Conversions between ROS's generated message types and uwscan's (messages.hpp). Includes ROS
// headers: only the C++17 translation units of ros/bridge include it.
#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/String.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include "ros/bridge/messages.hpp"

namespace uwscan::ros {

// Throws uwscan::Error when a stamp is negative, not finite or past ROS time's range.
::ros::Time ToRosTime(double stamp_s);

ImageMessage FromRos(const sensor_msgs::Image& message);
sensor_msgs::Image ToRos(const ImageMessage& message);

// Throws uwscan::Error naming the field when the pose or its covariance is not finite, or the
// orientation is not a unit quaternion (within 1e-3).
OdometryMessage FromRos(const nav_msgs::Odometry& message);
nav_msgs::Odometry ToRos(const OdometryMessage& message);

// Throws like the odometry's conversion.
TransformMessage FromRos(const geometry_msgs::TransformStamped& message);
geometry_msgs::TransformStamped ToRos(const TransformMessage& message);
std::vector<TransformMessage> FromRos(const tf2_msgs::TFMessage& message);
tf2_msgs::TFMessage ToRos(const std::vector<TransformMessage>& transforms);

sensor_msgs::PointCloud2 ToRos(const CloudMessage& message);
// Fields x, y, z (float32 or float64); points with a non-finite coordinate are left out.
// Throws uwscan::Error when a coordinate field is missing, of another type, or the data is
// shorter than its shape says.
CloudMessage FromRos(const sensor_msgs::PointCloud2& message);
nav_msgs::Path ToRos(const PathMessage& message);
geometry_msgs::PoseWithCovarianceStamped ToRos(const PoseMessage& message);
geometry_msgs::PoseArray ToRos(const PoseArrayMessage& message);
visualization_msgs::MarkerArray ToRos(const std::vector<MarkerMessage>& markers);
StringMessage FromRos(const std_msgs::String& message);
std_msgs::String ToRos(const StringMessage& message);

}  // namespace uwscan::ros
