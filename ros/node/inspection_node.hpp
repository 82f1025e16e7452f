#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mapping/change/live_deviation.hpp"
#include "mapping/inspection/live_inspection.hpp"
#include "ros/bridge/ros_connection.hpp"
#include "ros/conversions/navigation_input.hpp"
#include "ros/conversions/ros_names.hpp"
#include "ros/node/latency_by_minute.hpp"
#include "scanner/acquisition/frame_source.hpp"
#include "scanner/stripe/stripe_detector.hpp"

// Online inspection on the vehicle (`uwscan ros inspect`): the same LiveInspection as
// `uwscan inspect`, fed by ROS. Frames come from an image topic (frame_image.hpp), the
// navigation from nav_msgs/Odometry; every frame and navigation sample is logged, and each frame
// is placed with the navigation interpolated at its own stamp (frames wait for it). Publishes
// each sweep (PointCloud2 in the camera frame at its last frame), the map (PointCloud2, latched)
// and the SLAM and the navigation's paths at the submaps' anchors (nav_msgs/Path, both in the
// map frame, which is the navigation's world corrected) at most every map_period_s and within
// 10 % of the mapping thread, the correction map -> odom on /tf after every submap, and the
// latest anchor's pose with its covariance (the covariance within 5 % of the mapping thread).
namespace uwscan::ros {

// Frames straight from a camera (Aravis), as `uwscan inspect` reads them, instead of the image
// topic. Its clock must be the navigation's (a PTP-synchronised camera): frames are placed with
// the odometry at their camera time.
struct CameraInput {
  scanner::acquisition::CameraSettings settings;
  std::string scene;         // a simulated camera: the scene it serves
  std::string scanner_file;  // a real camera: its scanner (calibration) file
};

struct InspectionNodeOptions {
  std::optional<CameraInput> camera;  // std::nullopt: frames from topics.frames
  RosTopics topics;
  RosFrames frames;
  // Odometry or /tf, in uwscan's axes or REP 103's ENU/FLU (then the mount is read in FLU and
  // the map, paths and poses are published in ENU/FLU too).
  NavigationInput navigation;
  std::filesystem::path log;  // dive log to create ("" = none)
  // The scanner and scan pattern when given by the user; else the dive description on
  // topics.dive (a bag uwscan wrote, played) is waited for, up to description_wait_s.
  std::optional<mapping::DiveLogHeader> header;
  double description_wait_s = 30.0;  // seconds, > 0
  // The camera's mount is looked up on /tf_static (frames.base_link -> frames.camera) for up to
  // this long before the camera is taken at the vehicle's origin, seconds, >= 0.
  double mount_wait_s = 3.0;
  // The map and the paths are published at most this often, s, > 0; less often when they take
  // over a tenth of the time between them (late in long dives).
  double map_period_s = 2.0;
  int frame_queue = 4096;                   // frames roscpp holds while the node is busy, > 0
  scanner::StripeDetectorOptions detector;  // how image-mode frames are searched
  bool keep_images = false;                 // image-mode frames: log the images with the peaks
  mapping::InspectionOptions inspection;    // fixed_scanner is set false (navigation comes)
  std::string producer;                     // the log's producer
  // Stop once this many frames were received (0: no limit), or once frames stopped coming for
  // idle_stop_s after the first (0: never): for replays and tests.
  std::int64_t max_frames = 0;
  double idle_stop_s = 0.0;
  // When set, the published map carries each point's deviation from this reference (a float
  // field "deviation", metres, NaN where none; LiveDeviation), for RViz to colour by.
  std::shared_ptr<const mapping::LiveDeviation> reference;
  void Check() const;  // throws uwscan::Error naming the field
};

struct InspectionNodeSummary {
  mapping::InspectionResult result;
  std::int64_t frames_undecodable = 0;  // metadata row failed its checksum: not logged
  std::int64_t camera_lost_frames = 0;  // camera input: frames the camera sent that never arrived
  std::int64_t navigation_samples = 0;
  double receive_span_s = 0.0;  // from the first frame's arrival to the last one's
  std::int64_t sweeps_published = 0;
  // From the arrival of a sweep's last frame to its PointCloud2 being published, seconds.
  double sweep_latency_median_s = 0.0;
  double sweep_latency_p95_s = 0.0;
  std::vector<MinuteLatency> sweep_latency_by_minute;  // from the first sweep's minute
  std::int64_t maps_published = 0;
  // Maps the publishing thread had not taken before a newer one came (it publishes the newest).
  std::int64_t maps_replaced = 0;
  int reregistrations = 0;     // times the node registered again with a restarted master
  bool described = false;      // the scanner came from the dive topic
  std::string mount;           // where the camera's mount came from
  double time_origin_s = 0.0;  // ROS time of the log's time 0
  std::string stop_reason;
};

// What the node reports about once a second.
struct InspectionNodeStatus {
  mapping::InspectionStatistics statistics;
  bool master_reachable = true;
  double seconds = 0.0;          // since frames were first subscribed
  double frames_silent_s = 0.0;  // since the last frame came (0 before the first)
  std::int64_t navigation_samples = 0;
};

// Runs the node on `ros` until `stop_requested` says so, roscpp shuts down, or a limit in
// `options` is reached; then maps what is queued, closes the log and publishes the final map
// and paths. Throws uwscan::Error on a scanner that never came, a frame of the wrong encoding
// or size (naming the topic), a log that cannot be written, or mapping that failed; the log
// then holds every frame received before.
InspectionNodeSummary RunInspectionNode(
    RosConnection& ros, const InspectionNodeOptions& options,
    const std::function<bool()>& stop_requested,
    const std::function<void(const InspectionNodeStatus&)>& status);

}  // namespace uwscan::ros
