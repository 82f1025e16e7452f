#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "mapping/inspection/frame_recorder.hpp"
#include "mapping/log/dive_log.hpp"
#include "mapping/slam/mapper.hpp"
#include "mapping/slam/trajectory_metrics.hpp"
#include "perception/cloud/point_cloud.hpp"

// Online inspection (`uwscan inspect`, DESIGN.md "The three applications"): frames with their
// stripe peaks come in from a camera as fast as it delivers them; every one is logged, and the
// newest ones the mapper can keep up with are triangulated and mapped incrementally. The camera
// (Aravis), the stripe detector and the viewer stay outside: this is the pipeline between them.
namespace uwscan::mapping {

struct InspectionOptions {
  // Frames waiting for the disk before Push() waits for the log writer, bytes (FrameRecorder):
  // the log never drops a frame; when the disk stays behind beyond this, the camera reader
  // waits and the camera's next frames are lost upstream (and counted there). > 0.
  std::size_t log_queue_bytes = 512'000'000;
  // Frames waiting for the mapper, >= 1. The live path takes the newest frames: when a frame
  // comes while this many wait, the oldest waiting one is skipped (not mapped; it is logged).
  // Small, so that what is drawn is what the camera sees now.
  int live_queue_frames = 4;
  // No navigation: the scanner is held fixed, the vehicle at the world origin (T_W_V =
  // identity at every frame time), so sweeps of a static scene land on each other and the map
  // is in the vehicle frame. Loop closures are turned off then (the scanner does not move, there
  // is no drift to close). False: the caller feeds the vehicle's navigation (AddNavigation) and
  // frames wait in the mapper until it covers their time.
  bool fixed_scanner = true;
  // The mapping thread (and the OpenMP threads it starts) runs this much nicer than the caller,
  // [0, 19] (Linux nice increments): when the CPUs are short, receiving and recording frames,
  // which must not lose one, keep them, and the live map, which takes the newest frames and
  // skips the rest anyway, gets what is left.
  int mapper_nice = 10;
  // Online, a long dive's whole-graph solves run beside the mapping thread
  // (MapperOptions::whole_solve_lag_s), so that the live map does not stall for seconds.
  MapperOptions mapper = [] {
    MapperOptions online;
    online.whole_solve_lag_s = 10.0;
    return online;
  }();
  // Voxel of the map Finish() returns, metres, > 0; also the submaps' (it replaces
  // mapper.clouds.map_voxel_m: the map cannot be finer than its submaps).
  double map_voxel_m = 0.005;
  std::filesystem::path table_cache;  // triangulation tables kept between runs ("" = none)
  void Check() const;
};

// A frame handed to inspection: what the log records, and when it was taken and received.
struct InspectionFrame {
  FrameRecord record;  // record.index is ignored: frames are numbered as they are pushed
  // Host real-time clock (Unix time, seconds) when the camera exposed the frame, when the
  // camera's clock is the host's (PTP-synchronised, or the fake camera); nullopt otherwise.
  std::optional<double> capture_time_s;
  double receive_time_s = 0.0;  // host real-time clock (Unix time, seconds) when it arrived
};

// Latency of frames from an event to their points being placed in the map, over the most
// recent frames mapped (up to 65536 of them), seconds.
struct LatencyFigures {
  std::int64_t frames = 0;  // frames measured, all of them
  double median_s = 0.0;
  double p95_s = 0.0;
  double max_s = 0.0;  // over all frames measured
};

struct InspectionStatistics {
  std::int64_t frames_received = 0;  // pushed
  std::int64_t frames_logged = 0;    // committed to the dive log (when there is one)
  std::int64_t frames_mapped = 0;    // placed in the map
  std::int64_t frames_skipped = 0;   // pushed out of the live queue by newer frames
  // Navigation mode: no navigation around their time (MapperOptions::max_navigation_gap_s);
  // logged, not mapped.
  std::int64_t frames_without_navigation = 0;
  // Navigation mode: older than a frame already mapped (a camera that restarted its clock);
  // logged, not mapped. Fixed scanner: frames are renumbered on instead (clock_restarts).
  std::int64_t frames_out_of_order = 0;
  std::int64_t frames_waiting = 0;  // in the live queue or waiting in the mapper for navigation
  std::int64_t clock_restarts = 0;  // fixed scanner: times the camera's time or sweep went back
  std::int64_t points_mapped = 0;
  int submaps = 0;
  LatencyFigures capture_to_map;  // from the camera's exposure (frames with capture_time_s)
  LatencyFigures receive_to_map;  // from the host receiving the frame
  FrameRecorderStatistics log;
};

struct InspectionResult {
  InspectionStatistics statistics;
  perception::PointCloud map;         // voxelised at map_voxel_m, world frame (SLAM poses)
  std::vector<TimedPose> slam;        // T_W_V at each submap's anchor, estimated
  std::vector<TimedPose> navigation;  // T_W_V at each submap's anchor, as the navigation gave it
};

// A frame just placed in the map, for a live view (called on the mapping thread).
struct MappedFrame {
  std::int64_t index = 0;       // the frame's index in the log (push order)
  double time_s = 0.0;          // its capture time (the camera's clock, as logged)
  int sweep = 0;                // its sweep, as given
  double receive_time_s = 0.0;  // when it arrived (InspectionFrame::receive_time_s)
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
  std::span<const Eigen::Vector3d> points_W;  // valid during the call
};

// The pipeline: Push() logs every frame (FrameRecorder, its own writer thread; Push waits only
// when the disk is far behind) and puts it in a small live queue that a mapping thread drains
// into an incremental Mapper. Frames keep their order on both paths; the mapper sees a subset.
// Invariant: frames_received == frames_mapped + frames_skipped + frames_out_of_order +
// frames_waiting, at every statistics() call. Which frames are skipped depends on timing;
// with a live queue that never fills (a mapper faster than the camera) the map is the same
// as mapping every frame offline.
class LiveInspection {
 public:
  // `log`: the dive log to create, with `header` ("" = no log). T_V_C: the camera on the
  // vehicle; `noise`: how far the navigation is trusted (zeros for a fixed scanner).
  // `on_mapped` is called on the mapping thread for every frame placed. Throws uwscan::Error on
  // invalid options, a log that cannot be created, or a scanner that gives no triangulator.
  LiveInspection(const DiveLogHeader& header, const std::filesystem::path& log,
                 const Eigen::Isometry3d& T_V_C, const NavigationNoise& noise,
                 const InspectionOptions& options,
                 std::function<void(const MappedFrame&)> on_mapped = {});
  ~LiveInspection();  // stops the threads; call Finish() to see errors and the map
  LiveInspection(const LiveInspection&) = delete;
  LiveInspection& operator=(const LiveInspection&) = delete;

  // Logs the frame and offers it to the live queue. One thread pushes. Throws uwscan::Error
  // when the log writer or the mapping thread failed (the message says which), or after
  // Finish().
  void Push(InspectionFrame frame);
  // The vehicle's navigation (options.fixed_scanner false), in time order; thread-safe. Logged
  // with the frames (when there is a log). Throws like Push().
  void AddNavigation(const NavigationRecord& record);
  // Called on the mapping thread each time a submap closes (the mapper holds it, registered and
  // in the graph), with the mapper to read poses, covariances and the map from; nothing may be
  // added to the mapper there. Set it before the first Push().
  void SetSubmapClosedCallback(std::function<void(const Mapper&)> callback);
  // Maps the frames still queued, closes the log (every frame committed), finishes the mapper
  // (last submap, whole-graph solve) and returns the map. Throws like Push(), and when frames
  // were given to the mapper but no navigation ever covered them.
  InspectionResult Finish();
  InspectionStatistics statistics() const;  // thread-safe

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace uwscan::mapping
