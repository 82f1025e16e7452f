#include "perception/object_recognizer.hpp"

#include <omp.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include "perception/cloud_neighbors.hpp"
#include "perception/coarse_alignment.hpp"
#include "perception/icp.hpp"
#include "perception/normals.hpp"
#include "perception/object_database_builder.hpp"
#include "perception/plane_removal.hpp"
#include "perception/scan_segments.hpp"
#include "perception/view_pose_hypotheses.hpp"
#include "perception/voxel_filter.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

class StageClock {
 public:
  explicit StageClock(std::map<std::string, double>& seconds) : seconds_(seconds) {}
  void Lap(const std::string& stage) {
    const auto now = std::chrono::steady_clock::now();
    seconds_[stage] += std::chrono::duration<double>(now - last_).count();
    last_ = now;
  }

 private:
  std::map<std::string, double>& seconds_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// The `count` nearest views of each object by chi-square, nearest first: (distance, view index).
std::vector<std::vector<std::pair<double, int>>> NearestViews(const EsfDescriptor& esf,
                                                              const ObjectDatabase& db,
                                                              int count) {
  std::vector<std::vector<std::pair<double, int>>> nearest;
  for (const ObjectModel& o : db.objects) {
    std::vector<std::pair<double, int>> views;
    for (std::size_t v = 0; v < o.views.size(); ++v) {
      views.emplace_back(ChiSquareDistance(esf.data(), o.views[v].esf.data(), 640), static_cast<int>(v));
    }
    const auto keep = views.begin() + std::min<std::ptrdiff_t>(count, std::ssize(views));
    std::partial_sort(views.begin(), keep, views.end());
    views.erase(keep, views.end());
    if (views.empty()) views.emplace_back(std::numeric_limits<double>::infinity(), -1);
    nearest.push_back(std::move(views));
  }
  return nearest;
}

// The view's points with normals (facing its camera at the origin) and FPFH at every one.
struct ViewFeatures {
  PointCloud cloud;
  FpfhFeatures features;
};
ViewFeatures DescribeView(const ObjectView& view, const ObjectDatabaseParameters& p, int threads) {
  NormalOptions normals;
  normals.radius_m = p.normal_radius_m;
  normals.threads = threads;
  ViewFeatures v;
  v.cloud = AttachNormals(view.cloud, EstimateNormals(view.cloud, normals)).cloud;
  std::vector<std::size_t> all(v.cloud.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  v.features = ComputeFpfh(v.cloud, all, FpfhOptions{p.feature_radius_m, threads});
  return v;
}

// Directions from the sensor (at the origin) as two angles about a mean line of sight, well
// defined over the half space ahead of it whatever way the sensor's axes point.
class SightAngles {
 public:
  explicit SightAngles(const Eigen::Vector3d& forward)
      : w_(forward.normalized()), u_(w_.unitOrthogonal()), v_(w_.cross(u_)) {}
  Eigen::Vector2d operator()(const Eigen::Vector3d& p) const {
    const double z = p.dot(w_);
    return {std::atan2(p.dot(u_), z), std::atan2(p.dot(v_), z)};
  }

 private:
  Eigen::Vector3d w_, u_, v_;
};

// What the scan saw around one segment: all its points (scan frame, planes too) and their index,
// the segment's window of directions (where the sweep is known to have looked) and, over
// direction bins about `radius_m` wide at the segment, the nearest depth of any scan point.
using Bin = std::pair<long, long>;
struct SceneAround {
  const PointCloud& points;
  const KnnIndex& index;
  SightAngles angles;
  double bin_rad = 0.0;
  Eigen::Vector2d lo, hi;  // the segment's angular window, one bin of margin
  std::map<Bin, double> nearest_depth;

  Bin BinOf(const Eigen::Vector2d& a) const { return {std::lround(a.x() / bin_rad), std::lround(a.y() / bin_rad)}; }
  bool InWindow(const Eigen::Vector2d& a) const { return (a.array() >= lo.array()).all() && (a.array() <= hi.array()).all(); }
  // Some scan point, of anything, within a bin of this direction: the sweep looked there.
  bool Covered(const Bin& bin) const {
    for (long du = -1; du <= 1; ++du) {
      for (long dv = -1; dv <= 1; ++dv) {
        if (nearest_depth.count({bin.first + du, bin.second + dv}) != 0) return true;
      }
    }
    return false;
  }
};

SceneAround SceneAroundSegment(const PointCloud& whole_scan, const KnnIndex& index, const PointCloud& segment,
                               double radius_m) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < segment.size(); ++i) centroid += segment.Point(i);
  centroid /= static_cast<double>(segment.size());
  SceneAround around{whole_scan, index, SightAngles(centroid.norm() > 0.0 ? centroid : Eigen::Vector3d::UnitZ()),
                     std::max(radius_m / std::max(centroid.norm(), 1e-3), 1e-4),
                     Eigen::Vector2d::Constant(1e9), Eigen::Vector2d::Constant(-1e9), {}};
  for (std::size_t i = 0; i < segment.size(); ++i) {
    const Eigen::Vector2d a = around.angles(segment.Point(i));
    around.lo = around.lo.cwiseMin(a);
    around.hi = around.hi.cwiseMax(a);
  }
  around.lo.array() -= around.bin_rad;
  around.hi.array() += around.bin_rad;
  for (std::size_t i = 0; i < whole_scan.size(); ++i) {
    const Eigen::Vector3d x = whole_scan.Point(i);
    const Eigen::Vector2d a = around.angles(x);
    if (!around.InWindow(a)) continue;
    auto [it, inserted] = around.nearest_depth.emplace(around.BinOf(a), x.norm());
    if (!inserted) it->second = std::min(it->second, x.norm());
  }
  return around;
}

// Share of the posed model's surface the sensor should have seen that has no scan point within
// `radius_m`. Seen: facing the sensor (not grazing), within the segment's window of directions
// (the sweep may have covered only part of the object), nearest to the sensor along its line of
// sight among the model's own points (a depth buffer over the scene's direction bins), so parts
// the object hides from itself are not expected, not behind anything else the scan saw nearer
// in that direction (an object in front, a pipe lying across it), and where the scan has some
// point, of anything, within a bin (a MEMS pattern or a fan covers a shape of its own, and
// what it did not light is not evidence; a missing part in front of a seabed is). Any scan
// point counts, not only the segment's: a valve's handle that occlusion cut off from its body
// into a segment of its own still shows that the handle is there, and the seabed points
// removed as a plane still show the object's lowest rim.
double MissingShare(const ObjectModel& o, const Eigen::Isometry3d& T_S_O, const SceneAround& scene,
                    double radius_m) {
  std::map<Bin, double> model_depth;
  std::vector<std::pair<Eigen::Vector3d, Bin>> facing;
  const Eigen::Matrix3d R = T_S_O.linear();
  for (std::size_t i = 0; i < o.model.size(); ++i) {
    const Eigen::Vector3d x = T_S_O * o.model.Point(i);
    const double depth = x.norm();
    if ((R * o.model.normals[i].cast<double>()).dot(-x / depth) < 0.3) continue;  // grazing or back
    const Eigen::Vector2d a = scene.angles(x);
    if (!scene.InWindow(a)) continue;  // not swept
    const Bin bin = scene.BinOf(a);
    auto [it, inserted] = model_depth.emplace(bin, depth);
    if (!inserted) it->second = std::min(it->second, depth);
    facing.emplace_back(x, bin);
  }
  std::vector<std::uint32_t> nearest;
  std::vector<float> squared;
  std::size_t expected = 0, missing = 0;
  for (const auto& [x, bin] : facing) {
    const double depth = x.norm();
    if (depth > model_depth[bin] + radius_m) continue;  // hidden by the object itself
    const auto in_front = scene.nearest_depth.find(bin);
    if (in_front != scene.nearest_depth.end() && in_front->second < depth - radius_m) continue;  // occluded
    if (!scene.Covered(bin)) continue;  // the sweep did not look there
    ++expected;
    scene.index.Query((x - scene.points.origin).cast<float>(), 1, nearest, squared);
    if (nearest.empty() || squared[0] > radius_m * radius_m) ++missing;
  }
  return expected == 0 ? 1.0 : static_cast<double>(missing) / static_cast<double>(expected);
}

// Share of the segment (object frame) within `distance_m` of the model's surface: the
// point-to-plane distance to the nearest model point, when that point is within `reach_m` (about
// the model's sample spacing, so that a point beside a thin part, on the part's tangent plane but
// off its surface, does not count).
double CloseShare(const PointCloud& model, const KnnIndex& model_index, const PointCloud& segment_O,
                  double distance_m, double reach_m) {
  std::vector<std::uint32_t> nearest;
  std::vector<float> squared;
  std::size_t close = 0;
  for (std::size_t i = 0; i < segment_O.size(); ++i) {
    const Eigen::Vector3d x = segment_O.Point(i);
    model_index.Query((x - model.origin).cast<float>(), 1, nearest, squared);
    if (nearest.empty() || squared[0] > reach_m * reach_m) continue;
    const Eigen::Vector3d n = model.normals[nearest[0]].cast<double>().normalized();
    close += std::abs(n.dot(x - model.Point(nearest[0]))) <= distance_m ? 1 : 0;
  }
  return segment_O.empty() ? 0.0 : static_cast<double>(close) / static_cast<double>(segment_O.size());
}

// Free directions from the ICP information (object frame, rotations about the model's centroid
// centre_O), and the covariance over the constrained ones.
void AnalyseInformation(const Matrix6d& information, double sigma_m, double length_m,
                        double ratio, const Eigen::Isometry3d& T_S_O,
                        const Eigen::Vector3d& centre_O, RecognizedObject& out) {
  // Rotations scaled by the object's radius so both halves are in metres before comparing.
  Matrix6d D = Matrix6d::Identity();
  D.topLeftCorner<3, 3>() *= 1.0 / length_m;
  const Matrix6d scaled = D * information * D;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(scaled);
  const double largest = eigen.eigenvalues().maxCoeff();
  Matrix6d inverse_scaled = Matrix6d::Zero();
  for (int k = 0; k < 6; ++k) {
    const Eigen::Matrix<double, 6, 1> u = eigen.eigenvectors().col(k);
    if (largest > 0.0 && eigen.eigenvalues()[k] > ratio * largest) {
      inverse_scaled += u * u.transpose() / eigen.eigenvalues()[k];
      continue;
    }
    FreeDirection f;
    f.kind = "unconstrained";
    const bool rotation = u.head<3>().norm() > u.tail<3>().norm();
    f.motion = rotation ? "rotation" : "translation";
    const Eigen::Vector3d axis_O = (rotation ? u.head<3>() : u.tail<3>()).normalized();
    f.axis_S = T_S_O.linear() * axis_O;
    f.point_S = T_S_O * centre_O;
    out.free_directions.push_back(f);
  }
  out.covariance = sigma_m * sigma_m * (D * inverse_scaled * D);
}

// Point-to-plane ICP of a segment onto a model, to the scale of the data.
IcpOptions FineIcp(double diameter_m, const ObjectDatabaseParameters& p, int threads) {
  IcpOptions icp;
  icp.method = IcpMethod::kPointToPlane;
  icp.max_correspondence_distance_m = {4.0 * p.voxel_m, 2.0 * p.voxel_m, 1.5 * p.voxel_m};
  icp.translation_tolerance_m = 0.01 * p.voxel_m;
  icp.rotation_tolerance_rad = icp.translation_tolerance_m / (0.5 * diameter_m);
  icp.relative_rmse_tolerance = 1e-6;
  icp.max_iterations = 300;
  icp.max_iterations_per_stage = 100;
  icp.threads = threads;
  return icp;
}

// Starting poses T_O_S of a segment on one object: FPFH + RANSAC onto its nearest view (when
// RANSAC finds one), then each of its nearest views rolled about the line of sight.
std::vector<Eigen::Isometry3d> PoseStarts(const PointCloud& segment, const FpfhFeatures& segment_features,
                                          const ObjectModel& model,
                                          const std::vector<std::pair<double, int>>& views,
                                          const ObjectDatabaseParameters& p,
                                          const RecognitionOptions& options) {
  std::vector<Eigen::Isometry3d> starts;
  const ObjectView& nearest = model.views[static_cast<std::size_t>(views.front().second)];
  const ViewFeatures described = DescribeView(nearest, p, options.threads);
  CoarseAlignmentOptions coarse;
  coarse.inlier_distance_m = 2.0 * p.voxel_m;
  coarse.max_iterations = 20000;
  coarse.min_inlier_fraction = 0.02;
  coarse.seed = options.seed;
  coarse.threads = options.threads;
  // The segment onto the view it resembles, which places it on the model.
  const RegistrationResult rough =
      AlignCoarse(segment, segment_features, described.cloud, described.features, coarse);
  if (rough.converged) starts.push_back(nearest.T_O_C * rough.T_target_source);
  for (int v = 0; v < std::min<int>(options.pose_views, std::ssize(views)); ++v) {
    const ObjectView& view = model.views[static_cast<std::size_t>(views[static_cast<std::size_t>(v)].second)];
    for (const Eigen::Isometry3d& T_O_S : ViewPoseHypotheses(segment, view, options.pose_rolls)) {
      starts.push_back(T_O_S);
    }
  }
  return starts;
}

// Half turns about the three principal axes of a cloud through its centroid.
std::vector<Eigen::Isometry3d> HalfTurns(const PointCloud& cloud) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < cloud.size(); ++i) centroid += cloud.Point(i);
  centroid /= static_cast<double>(cloud.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d d = cloud.Point(i) - centroid;
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
  std::vector<Eigen::Isometry3d> turns;
  for (int k = 0; k < 3; ++k) {
    turns.push_back(Eigen::Translation3d(centroid) *
                    Eigen::AngleAxisd(std::numbers::pi, eigen.eigenvectors().col(k)) *
                    Eigen::Translation3d(-centroid));
  }
  return turns;
}

// The starts worth a full ICP: each gets a short ICP on a strided subset of the segment, and
// where that took the `refined_starts` best distinct ones by fit (then by order) is returned,
// best first.
// The fit is taken at two voxels, where a start in the right basin already has the segment
// on the model and a wrong one does not.
// Parallel over starts, chosen in a fixed order: the same for any thread count.
std::vector<Eigen::Isometry3d> SiftStarts(const PointCloud& segment, const IcpTarget& target,
                                          const std::vector<Eigen::Isometry3d>& starts, double diameter_m,
                                          const ObjectDatabaseParameters& p,
                                          const RecognitionOptions& options) {
  std::vector<Eigen::Isometry3d> kept;
  const std::size_t sift = static_cast<std::size_t>(options.sift_points);
  const std::size_t stride = std::max<std::size_t>(1, (segment.size() + sift - 1) / sift);
  std::vector<std::size_t> every;
  for (std::size_t i = 0; i < segment.size(); i += stride) every.push_back(i);
  if (every.size() < 3 || starts.empty()) return kept;
  const PointCloud subset = Subset(segment, every);
  IcpOptions icp;
  icp.method = IcpMethod::kPointToPlane;
  // From a tenth of the object's size (a roll step off at its rim) down to the fine ICP's start.
  icp.max_correspondence_distance_m = {std::max(0.1 * diameter_m, 8.0 * p.voxel_m), 4.0 * p.voxel_m,
                                       2.0 * p.voxel_m};
  icp.max_iterations_per_stage = 8;
  icp.max_iterations = 20;
  icp.translation_tolerance_m = 0.1 * p.voxel_m;
  icp.rotation_tolerance_rad = icp.translation_tolerance_m / (0.5 * diameter_m);
  icp.relative_rmse_tolerance = 1e-3;
  icp.threads = 1;
  auto quick_icp = [&](const std::vector<Eigen::Isometry3d>& from, std::vector<double>& fitness,
                       std::vector<Eigen::Isometry3d>& moved) {
    const std::size_t first = moved.size();
    fitness.resize(first + from.size(), 0.0);
    moved.resize(first + from.size());
    const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (std::ptrdiff_t s = 0; s < std::ssize(from); ++s) {
      const RegistrationResult quick = AlignIcp(subset, target, from[static_cast<std::size_t>(s)], icp);
      fitness[first + static_cast<std::size_t>(s)] = quick.fitness;
      moved[first + static_cast<std::size_t>(s)] = quick.T_target_source;
    }
  };
  std::vector<double> fitness;
  std::vector<Eigen::Isometry3d> moved;
  quick_icp(starts, fitness, moved);
  // The best pose turned half a turn about each principal axis of the model: a nearly
  // symmetric object (a valve's body) fits either way, and only a detail (its handle) decides.
  const std::size_t best = static_cast<std::size_t>(
      std::max_element(fitness.begin(), fitness.end()) - fitness.begin());
  std::vector<Eigen::Isometry3d> flipped;
  for (const Eigen::Isometry3d& half_turn : HalfTurns(target.cloud())) flipped.push_back(half_turn * moved[best]);
  quick_icp(flipped, fitness, moved);
  std::vector<std::size_t> order(moved.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return fitness[a] > fitness[b]; });
  // Distinct poses only: starts that ended in the same basin are refined once.
  const double same_m = p.voxel_m, same_rad = p.voxel_m / (0.5 * diameter_m);
  for (std::size_t s : order) {
    if (kept.size() == static_cast<std::size_t>(options.refined_starts)) break;
    const bool repeat = std::any_of(kept.begin(), kept.end(), [&](const Eigen::Isometry3d& k) {
      const Eigen::Isometry3d d = k.inverse() * moved[s];
      return d.translation().norm() < same_m && Eigen::AngleAxisd(d.linear()).angle() < same_rad;
    });
    if (!repeat) kept.push_back(moved[s]);
  }
  return kept;
}

}  // namespace

void RecognitionOptions::Check() const {
  auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  if (!positive(plane_distance_m)) throw Error("recognition: plane_distance_m must be > 0");
  if (!(plane_min_fraction > 0.0 && plane_min_fraction <= 1.0)) {
    throw Error("recognition: plane_min_fraction must be in (0, 1]");
  }
  if (!positive(cluster_tolerance_m)) throw Error("recognition: cluster_tolerance_m must be > 0");
  if (!(attach_distance_m >= 0.0 && std::isfinite(attach_distance_m))) {
    throw Error("recognition: attach_distance_m must be >= 0");
  }
  if (min_segment_points < 10) throw Error("recognition: min_segment_points must be >= 10");
  if (max_candidates < 1) throw Error("recognition: max_candidates must be >= 1, got " + std::to_string(max_candidates));
  auto in_range = [](const char* field, int value, int lo, int hi) {
    if (value < lo || value > hi) {
      throw Error(std::string("recognition: ") + field + " must be in [" + std::to_string(lo) + ", " +
                  std::to_string(hi) + "], got " + std::to_string(value));
    }
  };
  in_range("pose_views", pose_views, 0, 64);
  in_range("pose_rolls", pose_rolls, 1, 360);
  in_range("sift_points", sift_points, 10, 100000);
  in_range("refined_starts", refined_starts, 1, 64);
  if (!positive(max_chi_square)) throw Error("recognition: max_chi_square must be > 0");
  if (!(min_fitness >= 0.0 && min_fitness <= 1.0) || !(max_missing >= 0.0 && max_missing <= 1.0) ||
      !(min_close >= 0.0 && min_close <= 1.0)) {
    throw Error("recognition: min_fitness, min_close and max_missing must be in [0, 1]");
  }
  if (!positive(close_distance_m)) throw Error("recognition: close_distance_m must be > 0");
  if (!(free_direction_ratio > 0.0 && free_direction_ratio < 1.0)) {
    throw Error("recognition: free_direction_ratio must be in (0, 1)");
  }
  if (threads < 0) throw Error("recognition: threads must be >= 0");
}

RecognitionResult RecognizeObjects(const PointCloud& scan, const ObjectDatabase& db,
                                   const RecognitionOptions& options) {
  options.Check();
  RequireValidCloud(scan, "scan", 1);
  if (db.objects.empty()) throw Error("recognition: the object database is empty");
  const ObjectDatabaseParameters& p = db.parameters;
  RecognitionResult result;
  StageClock clock(result.stage_seconds);

  const PointCloud down = VoxelDownsample(scan, VoxelFilterOptions{p.voxel_m});
  double largest_object_m = 0.0;
  for (const ObjectModel& o : db.objects) largest_object_m = std::max(largest_object_m, o.diameter_m);
  const PlaneRemovalResult removed = RemoveSupportPlanes(down, largest_object_m, options);
  for (const DetectedPlane& plane : removed.planes) result.plane_points += plane.inliers.size();
  clock.Lap("preprocess");

  const std::vector<Segment> found = Segments(removed.remaining, options);
  std::vector<std::vector<std::size_t>> clusters;
  for (const Segment& f : found) clusters.push_back(f.indices);
  // Every scan point goes to the segment of the voxel point nearest to it.
  std::vector<int> segment_of_down(down.size(), -1);
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    for (std::size_t i : clusters[c]) segment_of_down[removed.remaining_indices[i]] = static_cast<int>(c);
  }
  std::vector<std::vector<std::size_t>> segments(clusters.size());
  if (!clusters.empty()) {
    const KnnIndex down_index(down.points);
    std::vector<std::uint32_t> nearest;
    std::vector<float> squared;
    const Eigen::Vector3f shift = (scan.origin - down.origin).cast<float>();
    for (std::size_t i = 0; i < scan.size(); ++i) {
      down_index.Query(scan.points[i] + shift, 1, nearest, squared);
      const int s = segment_of_down[nearest[0]];
      if (s >= 0) segments[static_cast<std::size_t>(s)].push_back(i);
    }
  }
  clock.Lap("segment");

  const KnnIndex scene_index(down.points);
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    RecognizedObject object;
    object.object_id = "unknown";
    object.segment = segments[c];
    const PointCloud segment = Subset(removed.remaining, clusters[c]);
    const SceneAround around = SceneAroundSegment(down, scene_index, segment, 2.0 * p.voxel_m);
    for (std::size_t i = 0; i < segment.size(); ++i) object.centroid_S += segment.Point(i);
    object.centroid_S /= static_cast<double>(segment.size());

    NormalOptions normal_options;
    normal_options.radius_m = p.normal_radius_m;
    normal_options.threads = options.threads;
    const CloudWithNormals with_normals =
        AttachNormals(segment, EstimateNormals(segment, normal_options));
    const EsfResult esf = VoxelisedEsf(segment, p.voxel_m, options.seed);
    clock.Lap("describe");
    if (!esf.ok || with_normals.cloud.size() < 10) {
      result.objects.push_back(std::move(object));
      continue;
    }
    const std::vector<std::vector<std::pair<double, int>>> nearest_views =
        NearestViews(esf.histogram, db, std::max(1, options.pose_views));
    std::vector<std::pair<double, int>> nearest;
    for (const auto& views : nearest_views) nearest.push_back(views.front());
    std::vector<std::size_t> order(db.objects.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return nearest[a].first < nearest[b].first; });
    // The segment's own cluster's diameter (a bounding-box diagonal can exceed it by up to
    // sqrt(3); debris that joined it may lie beyond the object).
    const double extent = found[c].core_diameter_m;
    std::vector<std::size_t> candidates;
    for (std::size_t i : order) {
      if (static_cast<int>(candidates.size()) >= options.max_candidates) break;
      if (nearest[i].first > options.max_chi_square) break;
      if (extent > 1.1 * db.objects[i].diameter_m + 4.0 * p.voxel_m) continue;  // too big for it
      candidates.push_back(i);
    }
    clock.Lap("match");

    std::vector<std::size_t> all(with_normals.cloud.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
    const FpfhFeatures segment_features =
        ComputeFpfh(with_normals.cloud, all, FpfhOptions{p.feature_radius_m, options.threads});
    clock.Lap("describe");
    std::vector<RegistrationResult> fine(candidates.size());
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      const ObjectModel& model = db.objects[candidates[k]];
      RecognitionCandidate candidate;
      candidate.object_id = model.id;
      candidate.chi_square = nearest[candidates[k]].first;
      candidate.view = nearest[candidates[k]].second;
      const std::vector<Eigen::Isometry3d> starts =
          PoseStarts(with_normals.cloud, segment_features, model, nearest_views[candidates[k]], p, options);
      clock.Lap("coarse");
      const IcpTarget target(model.model);
      const KnnIndex model_index(model.model.points);
      const std::vector<Eigen::Isometry3d> sifted =
          SiftStarts(with_normals.cloud, target, starts, model.diameter_m, p, options);
      clock.Lap("sift");
      bool posed = false;
      for (const Eigen::Isometry3d& start : sifted) {
        const RegistrationResult refined = AlignIcp(with_normals.cloud, target, start,
                                                    FineIcp(model.diameter_m, p, options.threads));
        const Eigen::Isometry3d T_O_S = refined.T_target_source;
        const PointCloud segment_O = Transformed(segment, T_O_S);
        const double missing = MissingShare(model, T_O_S.inverse(), around, 2.0 * p.voxel_m);
        const double close =
            CloseShare(model.model, model_index, segment_O, options.close_distance_m, p.voxel_m);
        const double score = close * (1.0 - missing);
        const bool verified = refined.fitness >= options.min_fitness &&
                              close >= options.min_close && missing <= options.max_missing;
        if (posed && (candidate.verified > verified ||
                      (candidate.verified == verified && candidate.score >= score))) {
          continue;  // an earlier start did at least as well
        }
        posed = true;
        fine[k] = refined;
        candidate.T_S_O = T_O_S.inverse();
        candidate.fitness = refined.fitness;
        candidate.close = close;
        candidate.rmse_m = refined.inlier_plane_rmse;
        candidate.missing = missing;
        candidate.score = score;
        candidate.verified = verified;
      }
      object.candidates.push_back(candidate);
      clock.Lap("refine");
    }

    // The best verified candidate by score; the candidates listed best first.
    std::vector<std::size_t> ranking(object.candidates.size());
    for (std::size_t i = 0; i < ranking.size(); ++i) ranking[i] = i;
    std::stable_sort(ranking.begin(), ranking.end(), [&](std::size_t a, std::size_t b) {
      const RecognitionCandidate &x = object.candidates[a], &y = object.candidates[b];
      if (x.verified != y.verified) return x.verified;
      return x.score > y.score;
    });
    if (!ranking.empty() && object.candidates[ranking[0]].verified) {
      const std::size_t k = ranking[0];
      const RecognitionCandidate& best = object.candidates[k];
      const ObjectModel& model = db.objects[candidates[k]];
      object.object_id = best.object_id;
      object.score = best.score;
      object.chi_square = best.chi_square;
      object.T_S_O = best.T_S_O;
      double other = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < db.objects.size(); ++i) {
        if (i != candidates[k]) other = std::min(other, nearest[i].first);
      }
      object.margin = std::isfinite(other) ? other - best.chi_square : 0.0;
      for (const SymmetryAxis& s : model.symmetries) {
        FreeDirection f;
        f.kind = "symmetry";
        f.motion = "rotation";
        f.axis_S = best.T_S_O.linear() * s.axis_O;
        f.point_S = best.T_S_O * s.point_O;
        f.order = s.order;
        object.free_directions.push_back(f);
      }
      AnalyseInformation(fine[k].information, std::max(fine[k].inlier_plane_rmse, 1e-5),
                         0.5 * model.diameter_m, options.free_direction_ratio, best.T_S_O,
                         model.model.origin, object);
      for (const GraspFrame& g : model.grasps) {
        object.grasps_S.emplace_back(g.name, best.T_S_O * g.T_O_G);
      }
    }
    std::vector<RecognitionCandidate> sorted;
    for (std::size_t i : ranking) sorted.push_back(object.candidates[i]);
    object.candidates = std::move(sorted);
    clock.Lap("verify");
    result.objects.push_back(std::move(object));
  }
  return result;
}

}  // namespace uwscan::perception
