#include "mapping/slam/dive_mapping.hpp"

#include <chrono>
#include <string>

#include "mapping/slam/map_uncertainty.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::mapping {
namespace {

// Every this many points of each submap go into the expected map error: an RMS over tens of
// thousands of points, not millions.
constexpr std::size_t kExpectedErrorStride = 8;

}  // namespace

void DiveMappingOptions::Check() const {
  mapper.Check();
  OptionChecks("DiveMappingOptions").GreaterThan("map_voxel_m", map_voxel_m, 0.0, "m");
}

NavigationNoise AssumedNavigationNoise() {
  NavigationNoise noise;
  noise.position_walk_m_per_sqrt_s = 0.005;
  noise.heading_walk_rad_per_sqrt_s = 0.0005;
  noise.speed_scale_sigma = 0.01;
  noise.heading_bias_sigma_rad = 0.01;
  noise.depth_sigma_m = 0.005;
  noise.roll_pitch_sigma_rad = 0.002;
  return noise;
}

namespace {

void RequireMappable(const DiveLogReader& log, const std::vector<NavigationRecord>& navigation,
                     const std::string& name) {
  if (navigation.empty()) {
    throw Error(name +
                " has no navigation: mapping places each frame with the vehicle's navigation");
  }
  const std::int64_t frame_count = log.frame_count();
  if (frame_count < 2) {
    throw Error(name + " has " + std::to_string(frame_count) + " frame" +
                (frame_count == 1 ? "" : "s") + ": mapping needs at least a sweep of frames");
  }
}

struct FrameSpan {
  double first_s = 0.0, last_s = 0.0;
};

// Times the mapper's calls and hands the time spent since the last submap closed to each new
// one (DiveMapping::submap_seconds), in all and by stage.
class SubmapClock {
 public:
  SubmapClock(const Mapper& mapper, DiveMapping* result) : mapper_(mapper), result_(result) {}
  template <typename Call>
  void Time(Call&& call) {
    const auto start = std::chrono::steady_clock::now();
    call();
    pending_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    while (static_cast<int>(result_->submap_seconds.size()) < mapper_.submap_count()) {
      result_->submap_seconds.push_back(pending_s_);
      result_->submap_stage_seconds.push_back(StagesSinceLastSubmap());
      pending_s_ = 0.0;
    }
  }

 private:
  MapperStageSeconds StagesSinceLastSubmap() {
    const MapperStageSeconds now = mapper_.stats().stage_seconds;
    const MapperStageSeconds since = now - last_;
    last_ = now;
    return since;
  }

  const Mapper& mapper_;
  DiveMapping* result_;
  double pending_s_ = 0.0;
  MapperStageSeconds last_;
};

// The log replayed as the vehicle delivered it: each navigation sample before the frames it
// precedes.
FrameSpan Replay(const DiveLogReader& log, const std::vector<NavigationRecord>& navigation,
                 Mapper& mapper, const std::function<void(double)>& progress, DiveMapping* result) {
  const double frame_count = static_cast<double>(log.frame_count());
  SubmapClock clock(mapper, result);
  std::size_t next_nav = 0;
  std::int64_t done = 0;
  FrameSpan span;
  log.ForEachFrame(
      [&](const FrameRecord& frame, const GroundTruthRecord*) {
        while (next_nav < navigation.size() && navigation[next_nav].time_s <= frame.time_s) {
          clock.Time([&] { mapper.AddNavigation(navigation[next_nav++]); });
        }
        clock.Time([&] { mapper.AddFrame(frame); });
        if (done == 0) span.first_s = frame.time_s;
        span.last_s = frame.time_s;
        ++done;
        if (progress) progress(static_cast<double>(done) / frame_count);
      },
      /*with_truth=*/false);
  while (next_nav < navigation.size())
    clock.Time([&] { mapper.AddNavigation(navigation[next_nav++]); });
  clock.Time([&] { mapper.Finish(); });
  return span;
}

void RequireMapped(const Mapper& mapper, const std::vector<NavigationRecord>& navigation,
                   const FrameSpan& span, double max_navigation_gap_s, const std::string& name) {
  if (mapper.stats().frames == 0) {
    throw Error(name + ": no frame lies within its navigation (samples from " +
                std::to_string(navigation.front().time_s) + " to " +
                std::to_string(navigation.back().time_s) + " s, at most " +
                std::to_string(max_navigation_gap_s) + " s apart; frames from " +
                std::to_string(span.first_s) + " to " + std::to_string(span.last_s) + " s)");
  }
  if (mapper.submap_count() == 0) throw Error(name + ": no frame gave points to map");
}

// The SLAM, dead-reckoned and (simulated dives) true vehicle poses at the submaps' anchors.
void AddTrajectories(const DiveLogReader& log, const Mapper& mapper, const Eigen::Isometry3d& T_V_C,
                     bool keep_submaps, DiveMapping& result) {
  const Eigen::Isometry3d T_C_V = T_V_C.inverse();
  for (int i = 0; i < mapper.submap_count(); ++i) {
    const Submap& s = mapper.submap(i);
    result.slam.push_back({s.anchor_time_s, mapper.pose(i)});
    result.dead_reckoning.push_back({s.anchor_time_s, s.T_W_V_nav});
    if (keep_submaps) result.submap_clouds.push_back(mapper.submap_clouds(i)->cloud);
    if (const std::optional<GroundTruthRecord> truth = log.ReadGroundTruth(s.anchor_frame)) {
      result.truth.push_back({s.anchor_time_s, truth->T_W_C * T_C_V});
    }
  }
  if (result.truth.size() != result.slam.size()) result.truth.clear();
}

// What the poses' covariances say the trajectory's and the map's errors come to.
void AddExpectedErrors(const Mapper& mapper, DiveMapping& result) {
  const std::optional<Mapper::SubmapCovariances> covariances = mapper.Covariances();
  if (!covariances) return;
  result.covariances = covariances->anchors;
  result.joint_uncertainty = mapper.JointUncertainty();
  result.expected_position_error_m = ExpectedPositionErrorRms(covariances->anchors);
  ExpectedSurfaceError error(kExpectedErrorStride);
  for (int i = 0; i < mapper.submap_count(); ++i) {
    error.Add(mapper.submap_clouds(i)->cloud, mapper.scan_pose(i),
              covariances->scans[static_cast<size_t>(i)], static_cast<std::size_t>(i));
  }
  result.expected_map_error_m = error.Rms();
}

}  // namespace

DiveMapping MapDive(const DiveLogReader& log, const DiveMappingOptions& options,
                    const std::function<void(double)>& progress) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  const std::string name = "dive log '" + log.path().string() + "'";
  const std::vector<NavigationRecord> navigation = log.ReadNavigation();
  RequireMappable(log, navigation, name);
  const DiveLogHeader& header = log.header();
  DiveMapping result;
  result.navigation_noise_assumed = !header.navigation_noise.has_value();
  const Eigen::Isometry3d T_V_C = log.vehicle_mount().value_or(Eigen::Isometry3d::Identity());
  Mapper mapper(header.scanner, header.scan_pattern, T_V_C,
                header.navigation_noise.value_or(AssumedNavigationNoise()), options.mapper,
                options.table_cache);
  const FrameSpan span = Replay(log, navigation, mapper, progress, &result);
  RequireMapped(mapper, navigation, span, options.mapper.max_navigation_gap_s, name);
  result.submaps = mapper.submap_count();
  AddTrajectories(log, mapper, T_V_C, options.keep_submaps, result);
  AddExpectedErrors(mapper, result);
  result.loops = mapper.loops();
  result.inconsistent_registrations = mapper.inconsistent_registrations();
  result.map = mapper.Map(options.map_voxel_m);
  result.stats = mapper.stats();
  result.calibration = mapper.calibration();
  result.dive_duration_s = span.last_s - span.first_s;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace uwscan::mapping
