#include "mapping/reconstruction/incremental_reconstruction.hpp"

#include <limits>

#include "scanner/common/error.hpp"
#include "scanner/triangulation/triangulator_factory.hpp"

namespace uwscan::mapping {

IncrementalReconstructor::IncrementalReconstructor(const DiveLogReader& log,
                                                   const ReconstructionOptions& options)
    : log_(log), options_(options) {
  triangulator_ = MakeLogTriangulator(log, options);
}

IncrementalReconstructor::~IncrementalReconstructor() = default;

void IncrementalReconstructor::UpdateNavigation(double frame_time_s, bool& read_this_poll) {
  if (read_this_poll || (navigation_ && navigation_->end_s() >= frame_time_s)) return;
  read_this_poll = true;  // once per poll: navigation that ends before the last frames is normal
  // The writer may append navigation as it goes: read it again once a frame outruns it.
  const std::vector<NavigationRecord> records = log_.ReadNavigation();
  if (records.empty()) return;
  scanner::sim::Trajectory trajectory;
  trajectory.T_V_C = log_.vehicle_mount().value_or(Eigen::Isometry3d::Identity());
  for (const NavigationRecord& r : records) {
    // Equal timestamps cannot be interpolated between: keep the first (as Reconstruct does).
    if (!trajectory.poses.empty() && !(r.time_s > trajectory.poses.back().time_s)) continue;
    trajectory.poses.push_back({r.time_s, r.T_W_V});
  }
  trajectory.Check();
  navigation_ = std::move(trajectory);
}

std::vector<ReconstructedFrame> IncrementalReconstructor::Poll(std::int64_t max_frames) {
  std::vector<ReconstructedFrame> out;
  const std::int64_t end = std::min(log_.frame_count(), next_frame_ + max_frames);
  std::vector<scanner::TriangulatedPoint> triangulated;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  bool navigation_read = false;
  for (; next_frame_ < end; ++next_frame_) {
    const FrameRecord frame = log_.ReadFrame(next_frame_);
    const std::optional<GroundTruthRecord> truth = log_.ReadGroundTruth(next_frame_);
    if (options_.use_navigation && world_frame_.value_or(true))
      UpdateNavigation(frame.time_s, navigation_read);
    if (!world_frame_) world_frame_ = navigation_.has_value();

    ReconstructedFrame r;
    r.index = frame.index;
    r.time_s = frame.time_s;
    r.sweep = frame.sweep;
    r.T_out_C = *world_frame_ ? navigation_->T_W_C(frame.time_s) : Eigen::Isometry3d::Identity();
    if (truth) r.true_T_W_C = truth->T_W_C;
    // Truth is stored in the world frame: bring it to the output frame.
    const Eigen::Isometry3d T_out_W =
        *world_frame_ || !truth ? Eigen::Isometry3d::Identity() : truth->T_W_C.inverse();
    triangulated.resize(frame.peaks_px.size());
    triangulator_->TriangulateFrame(frame.command, frame.peaks_px, triangulated);
    for (std::size_t i = 0; i < triangulated.size(); ++i) {
      if (!triangulated[i].ok()) continue;
      r.points.push_back(r.T_out_C * triangulated[i].p_C);
      if (!truth) continue;
      const bool has_truth = i < truth->points_W.size() && truth->points_W[i].allFinite();
      r.truth.push_back(has_truth ? Eigen::Vector3d(T_out_W * truth->points_W[i])
                                  : Eigen::Vector3d::Constant(nan));
      r.object_ids.push_back(i < truth->object_ids.size() ? truth->object_ids[i] : -1);
    }
    out.push_back(std::move(r));
  }
  return out;
}

}  // namespace uwscan::mapping
