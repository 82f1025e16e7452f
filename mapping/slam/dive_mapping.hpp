#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mapping/log/dive_log.hpp"
#include "mapping/slam/joint_pose_uncertainty.hpp"
#include "mapping/slam/mapper.hpp"
#include "mapping/slam/trajectory_metrics.hpp"
#include "perception/cloud/point_cloud.hpp"

namespace uwscan::mapping {

struct DiveMappingOptions {
  MapperOptions mapper;
  double map_voxel_m = 0.005;         // the output map's voxel, > 0
  std::filesystem::path table_cache;  // triangulation tables kept between runs ("" = none)
  bool keep_submaps = false;          // fill DiveMapping::submap_clouds
  void Check() const;
};

// A dive mapped offline: the log replayed through the online front end (Mapper), navigation and
// frames interleaved by time as the vehicle delivered them, then the whole graph solved.
struct DiveMapping {
  int submaps = 0;
  std::vector<TimedPose> slam;            // T_W_V of each submap's anchor, estimated
  std::vector<TimedPose> dead_reckoning;  // the navigation at the same times
  std::vector<TimedPose> truth;           // the truth at the same times (simulated logs only)
  std::vector<Matrix6d> covariances;      // per pose, [rotation, position] (empty: not computed)
  // How well the poses (slam, in order) are placed relative to each other: the graph's
  // information (Mapper::JointUncertainty); null with the covariances.
  std::shared_ptr<const JointPoseUncertainty> joint_uncertainty;
  // The map's expected distance to the true surfaces from its poses' uncertainty alone (RMS
  // along the normals, ExpectedSurfaceErrorRms); empty with the covariances.
  std::optional<double> expected_map_error_m;
  // The trajectory's expected RMS position error from the same covariances (what the ATE should
  // come to, ExpectedPositionErrorRms); empty with them.
  std::optional<double> expected_position_error_m;
  std::vector<LoopClosure> loops;
  std::vector<InconsistentRegistration> inconsistent_registrations;  // left to the navigation
  perception::PointCloud map;  // voxelised, world frame (SLAM poses)
  // Each submap's cloud in its own frame (normals attached), for peers that take the same
  // submaps; filled only when DiveMappingOptions::keep_submaps.
  std::vector<perception::PointCloud> submap_clouds;
  MapperStats stats;
  // The mapper's processing time for each submap, in order: its calls from the previous submap's
  // close to this one's (frames placed, the submap built, registered, loops tried, the graph
  // solved); reading the log excluded.
  std::vector<double> submap_seconds;
  // The same time by the mapper's stages (MapperStats' clocks), per submap in the same order.
  std::vector<MapperStageSeconds> submap_stage_seconds;
  DeadReckoningCalibration calibration;   // the DVL's scale error and misalignment as estimated
  bool navigation_noise_assumed = false;  // the log did not record it (schema 1)
  double dive_duration_s = 0.0;
  double seconds = 0.0;  // processing time, reading the log included
};

// The noise model assumed for a log that does not record one: a typical survey AUV (DVL dead
// reckoning ~1 % of distance travelled).
NavigationNoise AssumedNavigationNoise();

// Throws uwscan::Error naming the log when it has no navigation, fewer than two frames, or no
// submap with points. `progress` receives the fraction of frames done.
DiveMapping MapDive(const DiveLogReader& log, const DiveMappingOptions& options,
                    const std::function<void(double)>& progress = {});

}  // namespace uwscan::mapping
