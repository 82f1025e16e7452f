#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "mapping/log/dive_log.hpp"
#include "ros/conversions/navigation_input.hpp"
#include "ros/conversions/ros_names.hpp"
#include "scanner/stripe/stripe_detector.hpp"

// A ROS 1 bag turned into a dive log that `map`, `reconstruct`, `recognize` and `view` take:
// frames from an image topic (frame_image.hpp), navigation from nav_msgs/Odometry or /tf
// (navigation_input.hpp), the camera's
// mount from /tf_static, the scanner from the bag's dive description (a bag uwscan wrote) or
// from the caller (a vehicle's own bag).
namespace uwscan::ros {

struct BagImportOptions {
  RosTopics topics;  // frames, odometry (or /tf), dive description, /tf_static
  RosFrames frames;  // odom and base_link: the navigation's frames on /tf
  // Odometry or /tf; in uwscan's axes or ENU/FLU (then poses and the mount are turned).
  NavigationInput navigation;
  // The scanner the dive was taken with, when the bag carries no dive description (its
  // scan_pattern.kind set); a bag's own description wins over nothing but this.
  std::optional<mapping::DiveLogHeader> header;
  scanner::StripeDetectorOptions detector;  // how image-mode frames are searched
  bool keep_images = false;                 // image-mode frames: the images go into the log too
  std::string producer;                     // "uwscan bag import 0.1.0 (DIVE.bag)"
};

struct BagImportSummary {
  std::int64_t frames = 0;
  std::int64_t undecodable = 0;  // frames whose metadata row failed its checksum: left out
  std::int64_t navigation = 0;
  bool described = false;      // the bag carried a dive description (else options.header was used)
  double time_origin_s = 0.0;  // ROS time of the log's time 0
  // Where the mount came from: "/tf_static base_link -> uwscan_camera", or a note that none
  // was found and the camera is taken at the vehicle's origin.
  std::string mount;
};

// Writes `log` (which must not exist) from `bag`. The log appears only when the whole bag was
// read: it is written beside under a temporary name and renamed at the end. Throws
// uwscan::Error naming the bag, the topic and the field on: no frames or no odometry topic (the
// message lists the bag's topics), a topic of another type, no dive description and no
// options.header, an image of the wrong encoding or size, stamps that go back on a topic, a
// damaged or truncated bag.
BagImportSummary ImportBag(const std::filesystem::path& bag, const std::filesystem::path& log,
                           const BagImportOptions& options);

}  // namespace uwscan::ros
