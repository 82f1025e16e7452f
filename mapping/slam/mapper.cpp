#include "mapping/slam/mapper.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <future>

#include "mapping/slam/mapper_impl.hpp"
#include "mapping/slam/navigation_buffer.hpp"
#include "mapping/slam/navigation_uncertainty.hpp"
#include "mapping/slam/registration_information.hpp"
#include "perception/preprocessing/voxel_accumulator.hpp"
#include "perception/preprocessing/voxel_filter.hpp"
#include "perception/registration/icp.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/common/resident_memory.hpp"
#include "scanner/common/symmetrized.hpp"
#include "scanner/triangulation/triangulator_factory.hpp"

namespace uwscan::mapping {
namespace {

using mapper_steps::AppendMoved;
using mapper_steps::Clock;
using mapper_steps::Since;
using mapper_steps::SolvedGraph;

// Frames waiting for navigation beyond this many mean the navigation has stopped.
constexpr std::size_t kMaxWaitingFrames = 20000;
// The start fix: where the dive's dead reckoning starts is known to this much.
constexpr double kStartSigma_m = 0.001;
constexpr double kStartSigma_rad = 0.001;

// Information along world axes [w_W, t_W] holding only heading, x and y: the start fix.
Matrix6d StartInformation() {
  Matrix6d info = Matrix6d::Zero();
  info(2, 2) = 1.0 / (kStartSigma_rad * kStartSigma_rad);
  info(3, 3) = info(4, 4) = 1.0 / (kStartSigma_m * kStartSigma_m);
  return info;
}

// The ICP of a registration with the given stages, as MapperOptions sets it.
perception::IcpOptions RegistrationIcp(const MapperOptions& o,
                                       const std::vector<double>& distances) {
  perception::IcpOptions icp;
  icp.method = perception::IcpMethod::kPointToPlane;
  icp.max_correspondence_distance_m = distances;
  icp.max_iterations = o.icp_max_iterations;
  icp.max_iterations_per_stage = o.icp_max_iterations_per_stage;
  icp.translation_tolerance_m = o.icp_translation_tolerance_voxels * o.clouds.map_voxel_m;
  icp.rotation_tolerance_rad = o.icp_rotation_tolerance_rad;
  icp.relative_rmse_tolerance = o.icp_relative_rmse_tolerance;
  icp.early_stage_tolerance_scale = o.icp_early_stage_tolerance_scale;
  icp.threads = o.threads;
  return icp;
}

}  // namespace

void MapperOptions::Check() const {
  const OptionChecks check("MapperOptions");
  clouds.Check();
  check.GreaterThan("sweeps_per_submap", sweeps_per_submap, 0);
  check.GreaterThan("local_map_submaps", local_map_submaps, 0);
  check.GreaterThan("point_sigma_floor_m", point_sigma_floor_m, 0.0, "m");
  check.InRange("min_fitness", min_fitness, 0.0, 1.0);
  check.InRange("loop_min_fitness", loop_min_fitness, 0.0, 1.0);
  check.InRange("loop_min_directions", loop_min_directions, 1, 6);
  check.Require(loop_min_index_gap > local_map_submaps, "loop_min_index_gap",
                "> local_map_submaps (" + std::to_string(local_map_submaps) + ")",
                loop_min_index_gap);
  check.AtLeast("max_loop_candidates", max_loop_candidates, 0);
  check.GreaterThan("loop_every_submaps", loop_every_submaps, 0);
  check.GreaterThan("gate_sigmas", gate_sigmas, 0.0);
  check.InRange("loop_overlap_ratio", loop_overlap_ratio, 0.0, 1.0, Interval::kOpenLow);
  check.GreaterThan("loop_max_sigma_m", loop_max_sigma_m, 0.0, "m");
  check.GreaterThan("loop_max_sigma_rad", loop_max_sigma_rad, 0.0, "rad");
  check.GreaterThan("solve_every_submaps", solve_every_submaps, 0);
  check.GreaterThan("solve_window_submaps", solve_window_submaps, 0);
  check.AtLeast("solve_window_max_submaps", solve_window_max_submaps, solve_window_submaps);
  check.AtLeast("loop_window_chi2_per_direction", loop_window_chi2_per_direction, 0.0);
  check.GreaterThan("full_solve_growth", full_solve_growth, 1.0);
  check.NonNegative("whole_solve_lag_s", whole_solve_lag_s, "s");
  check.GreaterThan("resident_submaps", resident_submaps, local_map_submaps);
  check.InRange("running_solve_tolerance", running_solve_tolerance, 0.0, 1.0, Interval::kOpen);
  check.InRange("weak_direction_ratio", weak_direction_ratio, 0.0, 1.0, Interval::kOpenHigh);
  check.AtLeast("slide_sigma_m", slide_sigma_m, 0.0, "m");
  check.Positive("max_navigation_gap_s", max_navigation_gap_s, "s");
  check.NonNegative("navigation_latency_s", navigation_latency_s, "s");
  check.AtLeast("threads", threads, 0);
  check.GreaterThan("icp_max_iterations", icp_max_iterations, 0);
  check.GreaterThan("icp_max_iterations_per_stage", icp_max_iterations_per_stage, 0);
  check.GreaterThan("icp_translation_tolerance_voxels", icp_translation_tolerance_voxels, 0.0);
  check.GreaterThan("icp_rotation_tolerance_rad", icp_rotation_tolerance_rad, 0.0, "rad");
  check.InRange("icp_relative_rmse_tolerance", icp_relative_rmse_tolerance, 0.0, 1.0,
                Interval::kOpenHigh);
  check.AtLeast("icp_early_stage_tolerance_scale", icp_early_stage_tolerance_scale, 1.0);
  RegistrationIcp(*this, icp_distances_m).Check();
  RegistrationIcp(*this, loop_icp_distances_m).Check();
}

void Mapper::Impl::Drain(bool finishing) {
  while (!waiting.empty()) {
    const double t = waiting.front().time_s;
    bool place = false;
    if (navigation.Covers(t)) {
      place = navigation.GapAround(t) <= options.max_navigation_gap_s;
    } else if (navigation.empty() || t > navigation.last_time_s()) {
      // Waits for the navigation to reach it, unless it cannot be placed whatever comes: at the
      // end, or when frames much newer arrived (MapperOptions::navigation_latency_s).
      const bool hopeless =
          waiting.back().time_s - t > options.max_navigation_gap_s + options.navigation_latency_s;
      if (!finishing && !hopeless) break;
    }  // else: before the first sample, never covered
    if (place) {
      Place(waiting.front());
    } else {
      ++stats.frames_without_navigation;
      if (on_left_out) on_left_out(waiting.front());
    }
    waiting.pop_front();
  }
}

void Mapper::Impl::Place(const FrameRecord& frame) {
  if (!frames.empty() && frame.sweep >= first_sweep + options.sweeps_per_submap) CloseSubmap();
  if (frames.empty()) {
    first_sweep = frame.sweep;
    placement = graph.calibration();
    placement_origin_W = navigation.T_W_V(navigation.HeldTime(frame.time_s)).translation();
  }
  const Clock::time_point start = Clock::now();
  triangulated.resize(frame.peaks_px.size());
  triangulator->TriangulateFrame(frame.command, frame.peaks_px, triangulated);
  const Eigen::Isometry3d T_W_C = PlacementPose(frame.time_s) * T_V_C;
  const std::size_t first_point = points_W.size();
  for (const scanner::TriangulatedPoint& p : triangulated) {
    if (!p.ok()) continue;
    points_W.push_back(T_W_C * p.p_C);
    ++stats.points;
  }
  frames.emplace_back(frame.index, frame.time_s);
  ++stats.frames;
  stats.stage_seconds.triangulation_s += Since(start);
  if (on_placed) {
    on_placed(frame, T_W_C, std::span<const Eigen::Vector3d>(points_W).subspan(first_point));
  }
}

void Mapper::Impl::CloseSubmap() {
  if (frames.empty()) return;
  const Clock::time_point start = Clock::now();
  Submap submap;
  const auto& anchor = frames[frames.size() / 2];
  submap.anchor_frame = anchor.first;
  submap.anchor_time_s = anchor.second;
  submap.first_frame = frames.front().first;
  submap.last_frame = frames.back().first;
  submap.start_s = frames.front().second;
  submap.end_s = frames.back().second;
  const double t = navigation.HeldTime(anchor.second);
  submap.T_W_V_nav = navigation.T_W_V(t);
  const auto held_pose = [&](double time) { return navigation.T_W_V(navigation.HeldTime(time)); };
  submap.T_W_V_start = held_pose(submap.start_s);
  submap.T_W_V_end = held_pose(submap.end_s);
  // The points in the anchor's frame as the corrected navigation placed it.
  const Eigen::Isometry3d T_V_W = PlacementPose(anchor.second).inverse();
  std::vector<Eigen::Vector3d> points_V;
  points_V.reserve(points_W.size());
  for (const Eigen::Vector3d& p : points_W) points_V.push_back(T_V_W * p);
  SubmapCloudOptions cloud_options = options.clouds;
  cloud_options.viewpoint_V = T_V_C.translation();
  cloud_options.threads = options.threads;
  BuildSubmapClouds(points_V, cloud_options, &submap);
  const double last_time = frames.back().second;
  points_W.clear();
  frames.clear();
  navigation.DropBefore(last_time);
  stats.stage_seconds.submap_s += Since(start);
  // A submap that saw nothing (open water) adds no node: odometry bridges it.
  if (submap.cloud.empty() || submap.sparse.size() < 10) return;
  AddToGraph(std::move(submap));
}

perception::RegistrationResult Mapper::Impl::Register(const Submap& source,
                                                      const perception::PointCloud& target,
                                                      const Eigen::Isometry3d& T_init,
                                                      const Matrix6d& prior_covariance,
                                                      const std::vector<double>& distances) const {
  perception::IcpOptions icp = RegistrationIcp(options, distances);
  perception::IcpPrior prior;
  prior.T_target_source = T_init;
  prior.information = prior_covariance.inverse();
  prior.information = Symmetrized(prior.information);
  prior.point_sigma_m = 2.0 * options.point_sigma_floor_m;
  icp.prior = prior;
  return perception::AlignIcp(store.Get(source.index)->sparse, target, T_init, icp);
}

Matrix6d Mapper::Impl::RegistrationInformation(const perception::RegistrationResult& r,
                                               const Submap& target, const Submap& source,
                                               KeptDirections* kept) const {
  const double sigma = std::max(r.inlier_plane_rmse, options.point_sigma_floor_m);
  KeptDirections points =
      WithoutWeakDirections(r.information / (sigma * sigma), store.Get(source.index)->sparse,
                            r.T_target_source, options.weak_direction_ratio);
  // The pairs' residuals are not independent: what the navigation bent in each submap beyond a
  // rigid offset stays in every pair. Both submaps' bending floors the registration's covariance.
  const Matrix6d floor =
      uncertainty.BendingCovariance(target.end_s - target.start_s, target.rms_radius_m) +
      uncertainty.BendingCovariance(source.end_s - source.start_s, source.rms_radius_m);
  const Matrix6d information = InformationOfSum(points.information, floor);
  if (kept) *kept = std::move(points);
  return information;
}

Matrix6d Mapper::Impl::Distortion(const Submap& s, SystematicErrors systematic_errors) const {
  SweepPlacement sweep;
  sweep.T_W_start = s.T_W_V_start;
  sweep.T_W_anchor = s.T_W_V_nav;
  sweep.T_W_end = s.T_W_V_end;
  sweep.span_s = s.end_s - s.start_s;
  sweep.footprint_radius_m = s.rms_radius_m;
  sweep.footprint_centre_V = s.centroid_V;
  return uncertainty.SubmapDistortionCovariance(sweep, systematic_errors);
}

Matrix6d Mapper::Impl::MotionCovariance(const Submap& a, const Submap& b) const {
  const SystematicErrors systematic_errors = SystematicErrors::kAsNoise;
  const Eigen::Isometry3d T_a_b = a.T_W_V_nav.inverse() * b.T_W_V_nav;
  const Matrix6d ad = Adjoint(T_a_b);
  const Matrix6d covariance =
      uncertainty.IncrementCovariance(a.T_W_V_nav, b.T_W_V_nav, b.anchor_time_s - a.anchor_time_s,
                                      systematic_errors) +
      Distortion(a, systematic_errors) + ad * Distortion(b, systematic_errors) * ad.transpose();
  return Symmetrized(covariance);
}

void Mapper::Impl::AddToGraph(Submap submap) {
  const int k = static_cast<int>(submaps.size());
  submap.index = k;
  submap.surface_directions = SurfaceDirections(submap.cloud, options.weak_direction_ratio);
  store.Add({std::move(submap.cloud), std::move(submap.sparse)});
  submap.cloud = {};
  submap.sparse = {};
  const ConsecutiveRegistration c = RegisterToPrevious(submap, k);
  AddNodesAndEdges(submap, k, c);
  submaps.push_back(std::move(submap));
  increment_covariance.push_back(Symmetrized(c.increment_cov));
  CloseLoopsAndSolve(k);
  // No later window frees a submap before k + 1 - solve_window_max_submaps (FirstFreeSubmap):
  // what the graph measured among those goes to the spill file, read back by the whole solves.
  if (options.windowed_solves)
    graph.RetireBefore(AnchorNode(k + 1 - options.solve_window_max_submaps));
}

Mapper::Impl::ConsecutiveRegistration Mapper::Impl::RegisterToPrevious(const Submap& submap,
                                                                       int k) {
  ConsecutiveRegistration c;
  c.anchor_initial = submap.T_W_V_nav;
  c.scan_initial = submap.T_W_V_nav;
  if (k == 0) return c;
  const Submap& previous = submaps.back();
  const Eigen::Isometry3d T_nav =
      graph.calibration().CorrectMotion(previous.T_W_V_nav.inverse() * submap.T_W_V_nav);
  // The registration starts from the corrected navigation, and is judged against it, with
  // everything the navigation may be off by (the calibration may still be settling).
  c.increment_cov = MotionCovariance(previous, submap);
  // ICP starts from the previous scan where the graph now has it; the test below takes the
  // navigation's motion alone. Each scan's offset from its anchor is a distortion of zero mean,
  // which the covariance holds for both scans, so the graph's offset of the previous one is no
  // measurement to judge by: a loop that has just closed on that scan pulls it away from its
  // anchor, where nothing newer holds it yet (bench/slam/RESULTS.md, "Right registrations turned
  // away after a loop").
  const Eigen::Isometry3d T_predicted = ScanPose(k - 1).inverse() * AnchorPose(k - 1) * T_nav;
  c.anchor_initial = AnchorPose(k - 1) * T_nav;
  c.scan_initial = c.anchor_initial;

  const Clock::time_point start = Clock::now();
  const perception::RegistrationResult r =
      Register(submap, LocalMap(k), T_predicted, c.increment_cov, options.icp_distances_m);
  stats.stage_seconds.registration_s += Since(start);
  KeptDirections kept;
  const Matrix6d information = RegistrationInformation(r, previous, submap, &kept);
  const Vector6d innovation = PoseError(r.T_target_source, T_nav);
  const double chi2 = innovation.dot(InformationOfSum(information, c.increment_cov) * innovation);
  // Along a slide the registration measures nothing, so the test has as many degrees of
  // freedom as directions it pins.
  if (r.fitness >= options.min_fitness && chi2 <= Chi2Quantile999(kept.count)) {
    c.registration = RelativePoseEdge{.from = ScanNode(k - 1),
                                      .to = ScanNode(k),
                                      .T_from_to = r.T_target_source,
                                      .information = information};
    c.slides = SlideCovariance(kept.slides, r.T_target_source, options.slide_sigma_m);
    c.scan_initial = ScanPose(k - 1) * r.T_target_source;
    const Matrix6d combined = (c.increment_cov.inverse() + information).inverse();
    c.increment_cov = combined;
    ++stats.registrations;
  } else if (r.fitness >= options.min_fitness) {
    ++stats.registrations_inconsistent;
    inconsistent_registrations.push_back({.from = k - 1,
                                          .to = k,
                                          .T_from_to = r.T_target_source,
                                          .T_predicted = T_nav,
                                          .information = information});
  } else {
    ++stats.registrations_failed;
  }
  return c;
}

// The last local_map_submaps submaps before k, in the frame of the one just before it.
perception::PointCloud Mapper::Impl::LocalMap(int k) const {
  perception::PointCloud local;
  const Eigen::Isometry3d T_prev_W = ScanPose(k - 1).inverse();
  for (int j = std::max(0, k - options.local_map_submaps); j < k; ++j) {
    AppendMoved(store.Get(j)->cloud, T_prev_W * ScanPose(j), &local);
  }
  return local;
}

// Submap k's anchor and scan nodes, the distortion edge between them, the start prior or the
// odometry edge (and the registration) from the previous anchor, depth and gravity.
void Mapper::Impl::AddNodesAndEdges(const Submap& submap, int k, const ConsecutiveRegistration& c) {
  const NavigationNoise& noise = uncertainty.noise();
  const int anchor = graph.AddNode(c.anchor_initial);
  const int scan = graph.AddNode(c.scan_initial);
  if (anchor != AnchorNode(k) || scan != ScanNode(k))
    throw Error("mapper: graph nodes out of step with submaps");
  const Matrix6d distortion_information = (Distortion(submap, systematic()) + c.slides).inverse();
  graph.AddEdge({.from = anchor, .to = scan, .information = Symmetrized(distortion_information)});
  if (k == 0) {
    graph.AddPrior({.node = anchor, .T_W_V = submap.T_W_V_nav, .information = StartInformation()});
  } else {
    const Submap& previous = submaps.back();
    graph.AddEdge({.from = AnchorNode(k - 1),
                   .to = anchor,
                   .T_from_to = previous.T_W_V_nav.inverse() * submap.T_W_V_nav,
                   .information = uncertainty.OdometryInformation(
                       previous.T_W_V_nav, submap.T_W_V_nav,
                       submap.anchor_time_s - previous.anchor_time_s, systematic()),
                   .dead_reckoned = options.estimate_dead_reckoning_calibration});
    if (c.registration) graph.AddEdge(*c.registration);
  }
  graph.AddDepth(
      {.node = anchor, .z_m = submap.T_W_V_nav.translation().z(), .sigma_m = noise.depth_sigma_m});
  graph.AddGravity({.node = anchor,
                    .down_in_V = submap.T_W_V_nav.linear().transpose() * Eigen::Vector3d::UnitZ(),
                    .sigma_rad = noise.roll_pitch_sigma_rad});
}

// A solve after an accepted loop, else every solve_every_submaps submaps; a whole solve beside
// the dive applied when its time has come (or when the next one is due).
void Mapper::Impl::CloseLoopsAndSolve(int k) {
  const size_t tried_before = loops.size();
  TryLoopClosures(k);
  std::optional<int> oldest_loop;
  bool accepted = false;
  for (size_t i = tried_before; i < loops.size(); ++i) {
    const LoopClosure& loop = loops[i];
    accepted = accepted || loop.accepted;
    const double corrects =
        options.loop_window_chi2_per_direction * static_cast<double>(loop.constrained_directions);
    if (loop.accepted && loop.correction_chi2 > corrects)
      oldest_loop = std::min(oldest_loop.value_or(k), loop.from);
  }
  bool solve = accepted || ++since_solve >= options.solve_every_submaps;
  if (beside) {
    if (oldest_loop) beside->oldest_loop = std::min(beside->oldest_loop.value_or(k), *oldest_loop);
    const double anchor_s = submaps[static_cast<size_t>(k)].anchor_time_s;
    if (anchor_s >= beside->apply_at_s || FirstFreeSubmap(k, std::nullopt) == 0) {
      // The loops accepted since it was started were solved against the old poses.
      if (beside->oldest_loop)
        oldest_loop = std::min(oldest_loop.value_or(k), *beside->oldest_loop);
      ApplyWholeSolveBeside();
      solve = true;
    }
  }
  if (!solve) return;
  int first = FirstFreeSubmap(k, oldest_loop);
  if (first == 0 && SolvesBeside(k)) {
    StartWholeSolveBeside(k);
    first = FirstFreeSubmap(k, oldest_loop);
  }
  if (first > 0 && first < FirstFreeSubmap(k, std::nullopt)) ++stats.loop_window_solves;
  Solve(first);
}

bool Mapper::Impl::SolvesBeside(int k) const {
  return options.windowed_solves && options.whole_solve_lag_s > 0.0 && !beside &&
         k + 1 > options.solve_window_max_submaps;
}

// A copy of the graph solved whole on a thread of its own; the next whole solve is then due as
// if this one had been made now.
void Mapper::Impl::StartWholeSolveBeside(int k) {
  const Clock::time_point start = Clock::now();
  PoseGraphOptions solve;
  solve.function_tolerance = options.running_solve_tolerance;
  beside.emplace();
  beside->apply_at_s = submaps[static_cast<size_t>(k)].anchor_time_s + options.whole_solve_lag_s;
  // The copy is made here, where the graph does not grow meanwhile, and freed where it is solved.
  beside->solved = std::async(std::launch::async, [copy = graph.InMemoryCopy(), solve]() mutable {
    copy.Solve(solve);
    SolvedGraph solved{.poses = {}, .calibration = copy.calibration()};
    for (int node = 0; node < copy.node_count(); ++node) solved.poses.push_back(copy.pose(node));
    copy = PoseGraph();
    return solved;
  });
  const double grown = options.full_solve_growth * static_cast<double>(submaps.size());
  next_whole_solve_submaps = static_cast<int>(std::ceil(grown));
  stats.stage_seconds.graph_s += Since(start);
}

// Every node the copy held takes its solved pose; the nodes added since keep their place
// relative to the newest anchor it solved, moved with it. Waits for the solve if it runs still.
void Mapper::Impl::ApplyWholeSolveBeside() {
  const Clock::time_point start = Clock::now();
  {
    const SolvedGraph solved = beside->solved.get();
    const int nodes = static_cast<int>(solved.poses.size());
    // The newest submap's anchor in the copy carries the nodes added since.
    const Eigen::Isometry3d correction =
        solved.poses[static_cast<size_t>(nodes - 2)] * graph.pose(nodes - 2).inverse();
    for (int node = 0; node < graph.node_count(); ++node) {
      graph.set_pose(node, node < nodes ? solved.poses[static_cast<size_t>(node)]
                                        : correction * graph.pose(node));
    }
    if (graph.estimates_calibration()) graph.set_calibration(solved.calibration);
  }
  beside.reset();
  ReturnFreePages();  // as after a whole solve on this thread (Solve)
  ++stats.whole_solves;
  ++stats.whole_solves_beside;
  PlaceCentres(0, centres.held() - 1);
  stats.stage_seconds.graph_s += Since(start);
}

// The first submap a solve after submap k frees (MapperOptions::windowed_solves); 0: the whole
// graph.
int Mapper::Impl::FirstFreeSubmap(int k, std::optional<int> oldest_loop) const {
  const int submap_count = k + 1;
  if (!options.windowed_solves || submap_count >= next_whole_solve_submaps) return 0;
  int first = std::max(0, submap_count - options.solve_window_submaps);
  if (oldest_loop) first = std::min(first, *oldest_loop);
  return std::max(first, submap_count - options.solve_window_max_submaps);
}

void Mapper::Impl::Solve(int first_free_submap, bool last) {
  const Clock::time_point start = Clock::now();
  PoseGraphOptions solve;
  if (!last) solve.function_tolerance = options.running_solve_tolerance;
  if (first_free_submap == 0) {
    graph.Solve(solve);
    // The whole graph's problem (tens of megabytes on a long dive) is gone; its pages would
    // otherwise stay resident, a step up at every whole solve (bench/slam/RESULTS.md, "A graph
    // held as records").
    ReturnFreePages();
    ++stats.whole_solves;
    const double grown = options.full_solve_growth * static_cast<double>(submaps.size());
    next_whole_solve_submaps = static_cast<int>(std::ceil(grown));
  } else {
    graph.SolveWindow(AnchorNode(first_free_submap), solve);
    ++stats.window_solves;
  }
  PlaceCentres(first_free_submap, centres.held() - 1);
  since_solve = 0;
  stats.stage_seconds.graph_s += Since(start);
}

Mapper::Mapper(const scanner::Scanner& scanner, const scanner::ScanPattern& pattern,
               const Eigen::Isometry3d& T_V_C, const NavigationNoise& noise,
               const MapperOptions& options, const std::filesystem::path& table_cache)
    : impl_(std::make_unique<Impl>(options, T_V_C, noise)) {
  options.Check();
  if (impl_->options.estimate_dead_reckoning_calibration) {
    const NavigationNoise& floored = impl_->uncertainty.noise();
    impl_->graph.EstimateDeadReckoningCalibration(floored.speed_scale_sigma,
                                                  floored.heading_bias_sigma_rad);
  }
  scanner::TriangulatorBuildOptions build;
  build.table_cache = table_cache;
  impl_->triangulator = scanner::MakeTriangulator(
      scanner, pattern, scanner::DefaultTriangulationMethod(pattern.kind), build);
}

Mapper::~Mapper() = default;

void Mapper::SetFramePlacedCallback(FramePlacedCallback callback) {
  impl_->on_placed = std::move(callback);
}
void Mapper::SetFrameLeftOutCallback(FrameLeftOutCallback callback) {
  impl_->on_left_out = std::move(callback);
}

void Mapper::AddNavigation(const NavigationRecord& record) {
  if (impl_->finished) throw Error("mapper: navigation added after Finish");
  impl_->navigation.Add(record);
  impl_->Drain(false);
}

void Mapper::AddFrame(const FrameRecord& frame) {
  Impl& m = *impl_;
  if (m.finished) throw Error("mapper: frame added after Finish");
  if (!m.waiting.empty() && frame.time_s < m.waiting.back().time_s) {
    throw Error("mapper: frame " + std::to_string(frame.index) +
                " is older than the one before it");
  }
  if (m.waiting.size() >= kMaxWaitingFrames) {
    throw Error("mapper: " + std::to_string(m.waiting.size()) +
                " frames wait for navigation that does not come (last sample at " +
                (m.navigation.empty() ? std::string("none")
                                      : std::to_string(m.navigation.last_time_s()) + " s") +
                ")");
  }
  FrameRecord copy;
  copy.index = frame.index;
  copy.time_s = frame.time_s;
  copy.command = frame.command;
  copy.sweep = frame.sweep;
  copy.peaks_px = frame.peaks_px;  // the image is not needed once the peaks are found
  m.waiting.push_back(std::move(copy));
  m.Drain(false);
}

void Mapper::Finish() {
  Impl& m = *impl_;
  if (m.finished) return;
  if (m.navigation.empty()) throw Error("mapper: no navigation: frames cannot be placed");
  m.Drain(true);
  m.CloseSubmap();
  m.finished = true;
  if (m.beside) m.ApplyWholeSolveBeside();  // the last solve starts from its answer
  if (!m.submaps.empty()) m.Solve(/*first_free_submap=*/0, /*last=*/true);
}

int Mapper::submap_count() const { return static_cast<int>(impl_->submaps.size()); }
const Submap& Mapper::submap(int index) const {
  return impl_->submaps.at(static_cast<size_t>(index));
}
Eigen::Isometry3d Mapper::pose(int index) const {
  if (index < 0 || index >= submap_count())
    throw Error("mapper: no submap " + std::to_string(index));
  return impl_->AnchorPose(index);
}
Eigen::Isometry3d Mapper::scan_pose(int index) const {
  if (index < 0 || index >= submap_count())
    throw Error("mapper: no submap " + std::to_string(index));
  return impl_->ScanPose(index);
}
const std::vector<LoopClosure>& Mapper::loops() const { return impl_->loops; }
const std::vector<InconsistentRegistration>& Mapper::inconsistent_registrations() const {
  return impl_->inconsistent_registrations;
}
const MapperStats& Mapper::stats() const { return impl_->stats; }
DeadReckoningCalibration Mapper::calibration() const { return impl_->graph.calibration(); }

std::optional<Mapper::SubmapCovariances> Mapper::Covariances() const {
  const int n = submap_count();
  std::vector<int> nodes;
  for (int i = 0; i < n; ++i) nodes.push_back(impl_->AnchorNode(i));
  for (int i = 0; i < n; ++i) nodes.push_back(impl_->ScanNode(i));
  std::optional<std::vector<Matrix6d>> all = impl_->graph.Covariances(nodes);
  if (!all) return std::nullopt;
  SubmapCovariances out;
  out.anchors.assign(all->begin(), all->begin() + n);
  out.scans.assign(all->begin() + n, all->end());
  return out;
}

std::shared_ptr<const JointPoseUncertainty> Mapper::JointUncertainty() const {
  std::optional<Eigen::SparseMatrix<double>> information = impl_->graph.Information();
  if (!information) return nullptr;
  std::vector<int> columns;
  for (int i = 0; i < submap_count(); ++i) columns.push_back(6 * impl_->ScanNode(i));
  return std::make_shared<const JointPoseUncertainty>(std::move(*information), std::move(columns));
}

std::shared_ptr<const SubmapClouds> Mapper::submap_clouds(int index) const {
  if (index < 0 || index >= submap_count())
    throw Error("mapper: no submap " + std::to_string(index));
  return impl_->store.Get(index);
}

int Mapper::FirstMovableSubmap() const {
  if (!impl_->options.windowed_solves) return 0;
  return std::max(0, submap_count() - impl_->options.solve_window_max_submaps);
}

perception::PointCloud Mapper::Map(double voxel_m) const {
  if (submap_count() == 0) return {};
  // One submap at a time: the memory is the map's voxels, not every submap's points.
  perception::VoxelAccumulator map(voxel_m, scan_pose(0).translation());
  for (int i = 0; i < submap_count(); ++i) map.Add(submap_clouds(i)->cloud, scan_pose(i));
  return map.Cloud();
}

}  // namespace uwscan::mapping
