#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "mapping/log/dive_log.hpp"
#include "mapping/reconstruction/reconstruction.hpp"
#include "scanner/sim/trajectory.hpp"
#include "scanner/triangulation/triangulator.hpp"

namespace uwscan::mapping {

// One frame's points, placed as Reconstruct places them.
struct ReconstructedFrame {
  std::int64_t index = 0;
  double time_s = 0.0;
  int sweep = 0;
  Eigen::Isometry3d T_out_C = Eigen::Isometry3d::Identity();  // camera pose in the output frame
  std::optional<Eigen::Isometry3d> true_T_W_C;                // simulated logs
  std::vector<Eigen::Vector3d> points;   // in the output frame (world with navigation, else {C})
  std::vector<Eigen::Vector3d> truth;    // empty, or one per point (NaN where a peak has none)
  std::vector<std::int32_t> object_ids;  // empty, or one per point (scene object of its peak)
};

// A dive log reconstructed frame by frame while its writer may still be appending (a live view
// of a dive). The triangulator is built once, as in Reconstruct; each Poll() triangulates the
// frames committed since the previous one. Points are in the world frame when the log holds
// navigation at the first poll that finds a frame (re-read as later frames outrun it), in the
// camera frame otherwise (or when options.use_navigation is false), for every frame alike.
// Frame by frame the points equal Reconstruct's (tested).
class IncrementalReconstructor {
 public:
  // Throws uwscan::Error naming the log when its scanner cannot give a triangulator.
  IncrementalReconstructor(const DiveLogReader& log, const ReconstructionOptions& options);
  ~IncrementalReconstructor();

  // The frames committed since the last call (at most `max_frames` of them), in index order.
  // Throws uwscan::Error like DiveLogReader::ReadFrame.
  std::vector<ReconstructedFrame> Poll(std::int64_t max_frames = 1000);

  std::int64_t frames_done() const { return next_frame_; }
  bool world_frame() const { return world_frame_.value_or(false); }

 private:
  void UpdateNavigation(double frame_time_s, bool& read_this_poll);

  const DiveLogReader& log_;
  ReconstructionOptions options_;
  std::unique_ptr<scanner::Triangulator> triangulator_;
  std::optional<bool> world_frame_;  // decided at the first frame
  std::optional<scanner::sim::Trajectory> navigation_;
  std::int64_t next_frame_ = 0;
};

}  // namespace uwscan::mapping
