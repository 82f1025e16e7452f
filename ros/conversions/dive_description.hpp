#pragma once

#include <Eigen/Geometry>
#include <string>

#include "mapping/log/dive_log.hpp"

// What a dive log's header holds, carried in a bag as one latched std_msgs/String (YAML) on the
// dive topic (ros_names.hpp), so that a bag uwscan wrote imports without --scanner:
//
//   uwscan_format: 1
//   producer: "uwscan bag export 0.1.0 (...)"
//   time_origin_s: 1733097600      # ROS time of the dive log's time 0 (integer seconds)
//   scanner: |                     # the scanner file, verbatim (data/README.md)
//   scan_pattern: |                # the scan pattern (scanner/lasers/scan_pattern.hpp)
//   navigation_noise: {position_walk_m_per_sqrt_s: ..., ...}   # optional
//
// The camera's mount on the vehicle travels on /tf_static (base_link -> camera frame).
namespace uwscan::ros {

struct DiveDescription {
  mapping::DiveLogHeader header;  // scanner, scan pattern, producer, navigation noise
  // Dive-log time = ROS time - time_origin_s: simulated dives count from 0, ROS time from 1970.
  double time_origin_s = 0.0;
};

std::string DiveDescriptionToYaml(const DiveDescription& description);
// Throws uwscan::Error naming `source` and the field when the text is not such a description.
DiveDescription ParseDiveDescription(const std::string& yaml_text, const std::string& source);

}  // namespace uwscan::ros
