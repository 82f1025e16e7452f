#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "mapping/log/dive_log.hpp"
#include "mapping/slam/joint_pose_uncertainty.hpp"
#include "mapping/slam/pose_graph.hpp"
#include "mapping/slam/submap.hpp"
#include "mapping/slam/submap_store.hpp"
#include "perception/cloud/point_cloud.hpp"
#include "scanner/lasers/scan_pattern.hpp"
#include "scanner/lasers/scanner.hpp"
#include "scanner/triangulation/triangulator.hpp"

// Scan-matching SLAM, frame by frame: the front end that `uwscan map` replays a log through and
// that online inspection feeds live (mapping/README.md, "Scan-matching SLAM").
namespace uwscan::mapping {

struct MapperOptions {
  int sweeps_per_submap = 1;  // sweeps grouped into one submap, > 0
  SubmapCloudOptions clouds;  // voxel sizes, normals
  int local_map_submaps = 3;  // previous submaps the new one is registered to, > 0
  // ICP stages (metres, non-increasing) for consecutive submaps and for loop closures.
  std::vector<double> icp_distances_m = {0.04, 0.02, 0.01};
  std::vector<double> loop_icp_distances_m = {0.10, 0.04, 0.02, 0.01};
  // Every registration's ICP (point-to-plane, the prediction as its prior): iterations in all
  // and per stage (> 0), and when a stage has converged: once a step moves the data less than
  // this fraction of the map voxel (finer steps are the pairing flickering between neighbours,
  // not progress), turns it less than this angle, or lowers the RMSE by less than this fraction.
  int icp_max_iterations = 120;
  int icp_max_iterations_per_stage = 30;
  double icp_translation_tolerance_voxels = 0.05;
  double icp_rotation_tolerance_rad = 2e-5;
  double icp_relative_rmse_tolerance = 1e-4;
  // The stages before the last stop at this many times those tolerances (IcpOptions::
  // early_stage_tolerance_scale), >= 1.
  double icp_early_stage_tolerance_scale = 10.0;
  double point_sigma_floor_m = 0.0003;  // a point-to-plane residual is never trusted beyond this
  // A registration edge is kept only above this fitness, and only if it agrees with the
  // navigation's motion in the directions it pins (chi-square at 99.9 % for their number).
  double min_fitness = 0.3;
  // Loop closures: candidates at least this many submaps back, whose overlap is plausible
  // under the relative uncertainty (an error of Mahalanobis norm at most gate_sigmas brings
  // their centres within the overlap distance); at most max_loop_candidates tried per
  // submap. Accepted only if the registration's fitness, its own uncertainty in the directions
  // it pins and its consistency with the prediction there (chi-square) all agree.
  int loop_min_index_gap = 6;
  int max_loop_candidates = 1;
  // Loop closures are tried at every this many submaps, > 0. A sweep's footprint is several
  // times what the vehicle moves during it, so every other one still ties each stretch of a
  // revisit: over five seeds per dive, the same map error at 0.75x the mapping time.
  int loop_every_submaps = 2;
  double gate_sigmas = 3.0;
  // Two submaps overlap enough to match when their centres are closer than this fraction of
  // the sum of their radii (1 = they just touch).
  double loop_overlap_ratio = 0.6;
  double loop_min_fitness = 0.5;
  // A loop keeps the directions its pairs pin (weak_direction_ratio), at least this many: along
  // a pipe on a flat seabed it pins all but the slide along the pipe (5), over a bare seabed
  // only depth, roll and pitch (3), which the vehicle's own sensors already hold.
  int loop_min_directions = 5;
  double loop_max_sigma_m = 0.01;     // registration std along any kept direction
  double loop_max_sigma_rad = 0.005;  // registration std about any kept axis
                                      // (and chi-square at 99.9 % for the kept directions)
  int solve_every_submaps = 2;        // a solve also without a loop closure, > 0
  // What a solve during the dive frees, so that its cost does not grow with the dive: the last
  // solve_window_submaps submaps (> 0) and, after an accepted loop that corrects the graph (its
  // correction_chi2 over loop_window_chi2_per_direction times the directions it pins; >= 0,
  // infinity: no loop does), every submap back to the loop's older end, at most
  // solve_window_max_submaps (>= solve_window_submaps) in all; the submaps before stay where
  // they are. A loop the graph already meets within a fraction of the loop's own noise (a
  // chi-square of 1 per direction is that noise) would move the older submaps by less: it ties
  // the newest ones to them. The whole graph is solved once it holds full_solve_growth (> 1)
  // times the submaps it held at its last whole solve (the solves then cost a constant per
  // submap on average), and at Finish. false: every solve is whole.
  bool windowed_solves = true;
  int solve_window_submaps = 60;
  int solve_window_max_submaps = 400;
  double loop_window_chi2_per_direction = 0.5;
  double full_solve_growth = 1.5;
  // A whole solve of a graph of more than solve_window_max_submaps submaps (seconds of work on a
  // long dive) runs on a thread of its own, on a copy of the graph, while the dive goes on with
  // its window solves; its answer is applied at the first submap anchored this many seconds of
  // dive after the one that called for it (the mapper waits for it there if it is not done yet):
  // every submap it solved takes its pose, the newer ones keep theirs relative to the newest it
  // solved, and a window solve back to the oldest correcting loop since ties them together. The
  // same inputs give the same maps however fast that thread runs. Seconds, >= 0; 0: every whole
  // solve on the mapping thread, when called for (offline, where the total time counts, not a
  // stall: on two cores the solving thread slows the mapping by what it takes). Online
  // inspection and the ROS node use 10 s (InspectionOptions).
  double whole_solve_lag_s = 0.0;
  // The solves during the dive stop once an iteration lowers the cost by less than this
  // fraction (they only have to predict the next registrations and loops); the last one, in
  // Finish, goes to PoseGraphOptions' default. In (0, 1).
  double running_solve_tolerance = 1e-6;
  // Estimate the DVL's speed scale error and misalignment in the graph (odometry edges then
  // carry only the random walks) and place new frames with the corrected navigation; false:
  // both are treated as noise of each motion.
  bool estimate_dead_reckoning_calibration = true;
  // Registration directions whose normalised information is below this fraction of the
  // strongest are left to the navigation (WithoutWeakDirections, registration_information.hpp).
  double weak_direction_ratio = 0.02;
  // A scan whose registration leaves a slide free (a pipe without its ends in view) is tied to
  // its anchor along that slide only this loosely (metres): its place there is not measured,
  // and what the pairs leak along it must not pull the vehicle (SlideCovariance, mapper.cpp).
  double slide_sigma_m = 0.03;
  // A frame is placed only between navigation samples at most this far apart (seconds, > 0):
  // across a longer gap (a DVL that lost the bottom, a navigation that stopped) the
  // interpolated pose is a guess, so such a frame is left out and counted, as is one before the
  // first sample or, at Finish, after the last (MapperStats::frames_without_navigation).
  double max_navigation_gap_s = 1.0;
  // How far behind the frames the navigation may arrive (seconds, >= 0). A frame the
  // navigation has not reached once frames this much plus max_navigation_gap_s newer have come
  // is left out at once: the next sample, when it comes, is more than the gap away from the
  // last one before the frame, so the frame would be left out anyway. Frames then never pile up
  // waiting for a navigation that stopped.
  double navigation_latency_s = 1.0;
  int threads = 0;  // OpenMP threads of ICP and normals, 0 = default
  // Memory that does not grow with the dive: the clouds of all but the newest resident_submaps
  // submaps (> local_map_submaps) go to a spill file in this folder and are read back when a
  // loop or the map needs them (SubmapStore), and with windowed solves the graph's measurements
  // among submaps no window frees any more to another, read back by the whole solves
  // (PoseGraph::RetireBefore); empty: everything stays in memory.
  std::filesystem::path spill_folder;
  int resident_submaps = 64;
  void Check() const;
};

// How a LoopClosure's reason begins when the registration failed only the chi-square against the
// graph's prediction.
inline constexpr std::string_view kInconsistentLoop = "inconsistent with the prediction";

struct LoopClosure {
  int from = 0;  // the earlier submap
  int to = 0;    // the new one
  bool accepted = false;
  std::string reason;  // why it was rejected ("" when accepted)
  double fitness = 0.0;
  double chi2 = 0.0;  // of the registration against the prediction
  // Of the registration against the graph's estimate in the loop's own information alone: how
  // far the graph misses the loop, in the loop's own noise (1 per direction it pins). Set for
  // every loop tried; used for accepted ones (MapperOptions' windowed solves).
  double correction_chi2 = 0.0;
  int constrained_directions = 0;  // directions the registration pins (the rest are left free)
  // How far the graph's prediction of `to` in `from`'s frame may be off (m): the largest std of
  // its position, along the chain between them or through a loop accepted before.
  double prediction_std_m = 0.0;
  Eigen::Isometry3d T_from_to = Eigen::Isometry3d::Identity();  // as registered
  // What it measures ([w, v] in `from`'s frame, pose_graph.hpp): zero along the directions it
  // leaves free (the slide along a pipe), where T_from_to is only the prediction.
  Matrix6d information = Matrix6d::Zero();
};

// A submap's registration to the previous ones that its fitness allowed but the chi-square
// against the navigation's motion turned away (MapperStats::registrations_inconsistent): the
// submap was left to the navigation there. Kept so that a simulated dive's truth can tell a wrong
// registration from a right one judged against a prediction too sure of itself.
struct InconsistentRegistration {
  int from = 0;                                                   // the previous submap
  int to = 0;                                                     // the new one
  Eigen::Isometry3d T_from_to = Eigen::Isometry3d::Identity();    // as registered (scan to scan)
  Eigen::Isometry3d T_predicted = Eigen::Isometry3d::Identity();  // the navigation's motion
  Matrix6d information = Matrix6d::Zero();  // [w, v] in `from`'s frame, zero where it is free
};

// Processing time by stage (seconds): frames triangulated and placed, submaps voxelised with
// normals, registered to the last ones, loops tried, the graph solved.
struct MapperStageSeconds {
  double triangulation_s = 0.0;
  double submap_s = 0.0;
  double registration_s = 0.0;
  double loop_s = 0.0;
  double graph_s = 0.0;

  // Stage by stage: `a - b`, the time between two readings of the summed clocks; `+=` and
  // `*` to sum and average them.
  friend MapperStageSeconds operator-(const MapperStageSeconds& a, const MapperStageSeconds& b) {
    return {a.triangulation_s - b.triangulation_s, a.submap_s - b.submap_s,
            a.registration_s - b.registration_s, a.loop_s - b.loop_s, a.graph_s - b.graph_s};
  }
  friend MapperStageSeconds operator*(const MapperStageSeconds& a, double factor) {
    return {a.triangulation_s * factor, a.submap_s * factor, a.registration_s * factor,
            a.loop_s * factor, a.graph_s * factor};
  }
  MapperStageSeconds& operator+=(const MapperStageSeconds& b) {
    triangulation_s += b.triangulation_s;
    submap_s += b.submap_s;
    registration_s += b.registration_s;
    loop_s += b.loop_s;
    graph_s += b.graph_s;
    return *this;
  }
};

struct MapperStats {
  std::int64_t frames = 0;                     // placed
  std::int64_t frames_without_navigation = 0;  // left out: no navigation around their time
  std::int64_t points = 0;
  int registrations = 0;               // consecutive submaps registered (fitness above the floor)
  int registrations_failed = 0;        // left to odometry alone: fitness below the floor
  int registrations_inconsistent = 0;  // left to odometry alone: too far from the navigation
  MapperStageSeconds stage_seconds;    // summed over the dive so far
  int whole_solves = 0;                // of the whole graph
  int whole_solves_beside = 0;         // of those, solved beside the dive (whole_solve_lag_s)
  int window_solves = 0;               // of the last submaps only (MapperOptions::windowed_solves)
  int loop_window_solves = 0;          // of those, freed back to a correcting loop's older end
  // Loop closures not tried: the submap's own surface pins two directions fewer than a loop
  // must (Submap::surface_directions, MapperOptions::loop_min_directions).
  int loops_not_tried_plain = 0;
};

// Frames (stripe peaks) and navigation in, a pose graph of submaps out. Frames are queued until
// the navigation covers their time, then triangulated and placed with the navigation
// interpolated at their own time (frames the navigation does not cover are left out and
// counted, MapperOptions::max_navigation_gap_s); every `sweeps_per_submap` sweeps close a submap,
// which is registered (point-to-plane ICP with the navigation increment as start and prior) to the
// last few submaps, added to the graph with its odometry and registration edges and its depth and
// roll/pitch priors, and checked for loop closures against older submaps. The graph is
// re-solved when a loop closes (and every few submaps), in a window of the last submaps
// (MapperOptions::windowed_solves). Memory: the voxelised submaps and the
// graph, not the frames. Deterministic: the same inputs give the same bits for any thread count.
class Mapper {
 public:
  // T_V_C: the camera on the vehicle. Throws uwscan::Error on invalid options.
  Mapper(const scanner::Scanner& scanner, const scanner::ScanPattern& pattern,
         const Eigen::Isometry3d& T_V_C, const NavigationNoise& noise, const MapperOptions& options,
         const std::filesystem::path& table_cache = {});
  ~Mapper();
  Mapper(const Mapper&) = delete;
  Mapper& operator=(const Mapper&) = delete;

  // Called for every frame as it is placed (inside AddFrame, AddNavigation or Finish, on the
  // caller's thread), with the camera pose the navigation gave it and its triangulated points
  // in the navigation's world frame: what a live view draws, and the moment a frame's points
  // are in the map (the open submap). Set before the first frame.
  using FramePlacedCallback =
      std::function<void(const FrameRecord& frame, const Eigen::Isometry3d& T_W_C,
                         std::span<const Eigen::Vector3d> points_W)>;
  void SetFramePlacedCallback(FramePlacedCallback callback);
  // Called for every frame left out for want of navigation around its time (where and when
  // FramePlacedCallback would have been): every frame given is either placed or left out.
  using FrameLeftOutCallback = std::function<void(const FrameRecord& frame)>;
  void SetFrameLeftOutCallback(FrameLeftOutCallback callback);

  // Feed in time order (navigation may run ahead of frames; frames wait for it).
  void AddNavigation(const NavigationRecord& record);
  void AddFrame(const FrameRecord& frame);
  // Processes every frame still waiting (past the last navigation sample: left out and counted),
  // closes the last submap and solves the whole graph. Nothing may be added afterwards.
  void Finish();

  int submap_count() const;
  // A submap's place, times and shape; its clouds (empty here) come from submap_clouds.
  const Submap& submap(int index) const;
  // Read back from the spill file when they were spilled (MapperOptions::spill_folder).
  std::shared_ptr<const SubmapClouds> submap_clouds(int index) const;
  Eigen::Isometry3d pose(int index) const;  // current estimate of T_W_V at the submap's anchor
  // The pose its cloud is placed with: the anchor's, off by the bending of the navigation that
  // placed its frames (SubmapDistortionCovariance in navigation_uncertainty.hpp).
  Eigen::Isometry3d scan_pose(int index) const;
  const std::vector<LoopClosure>& loops() const;
  const std::vector<InconsistentRegistration>& inconsistent_registrations() const;
  const MapperStats& stats() const;
  // The dead reckoning's calibration as currently estimated (zero when not estimated).
  DeadReckoningCalibration calibration() const;
  // Per-submap marginal covariances ([rotation, position] in the world, pose_graph.hpp) of the
  // anchors (the vehicle's poses) and of the scans (the poses the clouds are placed with), from
  // one factorisation. std::nullopt when the graph leaves a direction unconstrained.
  struct SubmapCovariances {
    std::vector<Matrix6d> anchors, scans;
  };
  std::optional<SubmapCovariances> Covariances() const;
  // The anchors' joint uncertainty (the graph's information, each submap's anchor a pose in
  // order). Null when the graph cannot be evaluated.
  std::shared_ptr<const JointPoseUncertainty> JointUncertainty() const;
  // Every submap's cloud placed with the current estimates, voxelised at `voxel_m`, origin at
  // the first submap's position; the clouds are merged one at a time, so the memory it takes is
  // the map's.
  perception::PointCloud Map(double voxel_m) const;
  // The first submap a solve may still move before the next whole-graph solve (which moves
  // them all: MapperStats::whole_solves counts them). Windowed solves free at most the last
  // solve_window_max_submaps submaps of the graph as it will then be, so every submap before
  // that many from the end stays where it is; 0 when every solve is whole.
  int FirstMovableSubmap() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace uwscan::mapping
