#include "perception/recognition/scan_segments.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/preprocessing/clustering.hpp"

namespace uwscan::perception {
namespace {

// The smaller of a point set's two spans across a plane's normal, metres (sqrt(12) standard
// deviations: the width of a uniformly covered strip).
double NarrowSpan(const PointCloud& cloud, const DetectedPlane& plane) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t i : plane.inliers) mean += cloud.Point(i);
  mean /= static_cast<double>(plane.inliers.size());
  const Eigen::Matrix3d across =
      Eigen::Matrix3d::Identity() - plane.normal * plane.normal.transpose();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (std::size_t i : plane.inliers) {
    const Eigen::Vector3d d = across * (cloud.Point(i) - mean);
    scatter += d * d.transpose();
  }
  scatter /= static_cast<double>(plane.inliers.size());
  // Eigenvalues ascending: 0 along the normal, then the narrow and the wide in-plane variance.
  const Eigen::Vector3d variances =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvalues();
  return std::sqrt(12.0 * std::max(variances(1), 0.0));
}

// Planes removed as supports at most (the seabed and two walls), and planes looked at to find
// them (an object's face seen broadside is looked at and kept).
constexpr std::size_t kMaxSupportPlanes = 3;
constexpr double kFindingShare = 3.0;
constexpr double kBehindMargin = 1.5;
constexpr int kMaxPlaneSearches = 5;

// The inliers of `plane` within distance_m, and in `rest` the other points of `cloud`.
DetectedPlane WithInliers(const PointCloud& cloud, DetectedPlane plane, double distance_m,
                          std::vector<std::size_t>& rest) {
  plane.inliers.clear();
  rest.clear();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double d = plane.normal.dot(cloud.Point(i)) + plane.offset_m;
    (std::abs(d) < distance_m ? plane.inliers : rest).push_back(i);
  }
  return plane;
}

// Whether a plane hides surface behind it from the sensor at the origin: at least a tenth as
// many points as it holds (and a segment's worth) lie beyond it by more than 1.5 times
// plane_distance_m (a seabed dipping a little below its fitted plane does not count; a panel's
// 2 cm does).
bool HidesSurface(const PointCloud& cloud, const DetectedPlane& plane,
                  const RecognitionOptions& options) {
  const double sensor_side = plane.offset_m >= 0.0 ? 1.0 : -1.0;  // sign of n . 0 + offset
  std::size_t behind = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double distance_m = plane.normal.dot(cloud.Point(i)) + plane.offset_m;
    if (sensor_side * distance_m < -kBehindMargin * options.plane_distance_m) ++behind;
  }
  return behind >= std::max<std::size_t>(static_cast<std::size_t>(options.min_segment_points),
                                         plane.inliers.size() / 10);
}

// Each fragment joins the segment nearest to it when within `distance_m`.
void AttachFragments(const PointCloud& cloud,
                     const std::vector<std::vector<std::size_t>>& fragments, double distance_m,
                     std::vector<Segment>& segments) {
  if (segments.empty() || fragments.empty()) return;
  std::vector<Eigen::Vector3f> points;
  std::vector<std::size_t> owner;
  for (std::size_t k = 0; k < segments.size(); ++k) {
    for (std::size_t i : segments[k].indices) {
      points.push_back(cloud.points[i]);
      owner.push_back(k);
    }
  }
  const KnnIndex index(points);
  std::vector<std::uint32_t> nearest;
  std::vector<float> squared;
  for (const std::vector<std::size_t>& part : fragments) {
    float best = std::numeric_limits<float>::infinity();
    std::size_t to = 0;
    for (std::size_t i : part) {
      index.Query(cloud.points[i], 1, nearest, squared);
      if (squared[0] < best) best = squared[0], to = owner[nearest[0]];
    }
    if (best <= distance_m * distance_m) {
      segments[to].indices.insert(segments[to].indices.end(), part.begin(), part.end());
    }
  }
}

// Joins segments within `distance_m` of each other, the smallest first into its nearest, when
// together they are no wider than `widest_m`.
void JoinNearbySegments(const PointCloud& cloud, double widest_m, double distance_m,
                        std::vector<Segment>& segments) {
  bool joined = true;
  while (joined && segments.size() > 1) {
    joined = false;
    std::vector<std::size_t> order(segments.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return segments[a].indices.size() < segments[b].indices.size();
    });
    for (std::size_t k : order) {
      const auto [to, distance] = NearestSegment(cloud, segments[k].indices, segments, k);
      if (distance > distance_m) continue;
      std::vector<std::size_t> both = segments[to].indices;
      both.insert(both.end(), segments[k].indices.begin(), segments[k].indices.end());
      const double diameter = Diameter(Subset(cloud, both));
      if (diameter > widest_m) continue;
      segments[to] = {std::move(both), diameter};
      segments.erase(segments.begin() + static_cast<std::ptrdiff_t>(k));
      joined = true;
      break;
    }
  }
}

// Fragments within `attach_distance_m` of each other that together hold min_segment_points
// (and are no wider than `widest_m`) become a segment: an object that occlusion cut into pieces
// each too small to count, with no segment near enough to take them (a lever valve whose own
// handle's shadow split it in two halves of 110 points). The rest stay fragments.
void PromoteFragmentGroups(const PointCloud& cloud, double widest_m,
                           const RecognitionOptions& options,
                           std::vector<std::vector<std::size_t>>& fragments,
                           std::vector<Segment>& segments) {
  std::vector<std::size_t> points;  // into cloud
  for (const std::vector<std::size_t>& part : fragments)
    points.insert(points.end(), part.begin(), part.end());
  if (points.size() < static_cast<std::size_t>(options.min_segment_points)) return;
  ClusteringOptions grouping;
  grouping.tolerance_m = options.attach_distance_m;
  std::vector<std::vector<std::size_t>> rest;
  for (const std::vector<std::size_t>& group : EuclideanClusters(Subset(cloud, points), grouping)) {
    std::vector<std::size_t> members;
    for (std::size_t i : group) members.push_back(points[i]);
    std::sort(members.begin(), members.end());
    if (members.size() >= static_cast<std::size_t>(options.min_segment_points)) {
      const double diameter = Diameter(Subset(cloud, members));
      if (diameter <= widest_m) {
        segments.push_back({std::move(members), diameter});
        continue;
      }
    }
    rest.push_back(std::move(members));
  }
  fragments = std::move(rest);
}

}  // namespace

std::pair<std::size_t, double> NearestSegment(const PointCloud& cloud,
                                              const std::vector<std::size_t>& part,
                                              const std::vector<Segment>& segments,
                                              std::size_t skip) {
  std::vector<Eigen::Vector3f> points;
  std::vector<std::size_t> owner;
  for (std::size_t k = 0; k < segments.size(); ++k) {
    if (k == skip) continue;
    for (std::size_t i : segments[k].indices) {
      points.push_back(cloud.points[i]);
      owner.push_back(k);
    }
  }
  if (points.empty()) return {0, std::numeric_limits<double>::infinity()};
  const KnnIndex index(points);
  std::vector<std::uint32_t> nearest;
  std::vector<float> squared;
  float best = std::numeric_limits<float>::infinity();
  std::size_t to = 0;
  for (std::size_t i : part) {
    index.Query(cloud.points[i], 1, nearest, squared);
    if (squared[0] < best) best = squared[0], to = owner[nearest[0]];
  }
  return {to, std::sqrt(static_cast<double>(best))};
}

std::vector<Segment> Segments(const PointCloud& cloud, double largest_object_m,
                              const RecognitionOptions& options) {
  ClusteringOptions clustering;
  clustering.tolerance_m = options.cluster_tolerance_m;
  std::vector<Segment> segments;
  std::vector<std::vector<std::size_t>> small;
  for (std::vector<std::size_t>& c : EuclideanClusters(cloud, clustering)) {
    if (c.size() < static_cast<std::size_t>(options.min_segment_points)) {
      small.push_back(std::move(c));
      continue;
    }
    const double diameter = Diameter(Subset(cloud, c));
    segments.push_back({std::move(c), diameter});
  }
  PromoteFragmentGroups(cloud, largest_object_m, options, small, segments);
  AttachFragments(cloud, small, options.attach_distance_m, segments);
  JoinNearbySegments(cloud, largest_object_m, options.attach_distance_m, segments);
  for (Segment& segment : segments) std::sort(segment.indices.begin(), segment.indices.end());
  std::stable_sort(segments.begin(), segments.end(), [](const Segment& a, const Segment& b) {
    return a.indices.size() > b.indices.size();
  });
  return segments;
}

PlaneRemovalResult RemoveSupportPlanes(const PointCloud& down, double largest_object_m,
                                       const RecognitionOptions& options) {
  PlaneRemovalOptions planes;
  // Planes are found with a third of the inlier distance and then take their inliers within it
  // all: with the whole distance, RANSAC's best plane may straddle two parallel surfaces a little
  // more than it apart (a panel's face and the seabed or wall behind it), tilted to catch a strip
  // of each, where a third of it holds only the whole of one surface.
  planes.distance_threshold_m = options.plane_distance_m / kFindingShare;
  planes.max_planes = 1;
  planes.seed = options.seed;
  planes.threads = options.threads;
  std::vector<bool> removed(down.size(), false);
  std::vector<std::size_t> searched_indices(down.size());  // into down: where planes are sought
  for (std::size_t i = 0; i < down.size(); ++i) searched_indices[i] = i;
  PointCloud searched = down;
  PlaneRemovalResult result;
  for (int search = 0;
       search < kMaxPlaneSearches && result.planes.size() < kMaxSupportPlanes && !searched.empty();
       ++search) {
    // min_fraction is of the cloud handed over; keep it a share of the whole scan.
    planes.min_fraction =
        std::min(1.0, options.plane_min_fraction * static_cast<double>(down.size()) /
                          static_cast<double>(searched.size()));
    const PlaneRemovalResult step = RemovePlanes(searched, planes);
    if (step.planes.empty()) break;
    std::vector<std::size_t> rest;
    DetectedPlane plane =
        WithInliers(searched, step.planes.front(), options.plane_distance_m, rest);
    const bool wide = NarrowSpan(searched, plane) >= largest_object_m;
    for (std::size_t& i : plane.inliers) i = searched_indices[i];
    // A plane may be an object's face seen broadside (a panel, a plate): it hides the surface
    // behind it, where the seabed or a wall hides nothing. Its points stay in the scan; the
    // search goes on without them.
    const bool face = !wide && HidesSurface(down, plane, options);
    if (!face && !wide && !result.planes.empty()) break;
    searched = Subset(searched, rest);
    for (std::size_t& i : rest) i = searched_indices[i];
    searched_indices = std::move(rest);
    if (face) continue;
    for (std::size_t i : plane.inliers) removed[i] = true;
    result.planes.push_back(std::move(plane));
  }
  for (std::size_t i = 0; i < down.size(); ++i) {
    if (!removed[i]) result.remaining_indices.push_back(i);
  }
  result.remaining = Subset(down, result.remaining_indices);
  return result;
}

}  // namespace uwscan::perception
