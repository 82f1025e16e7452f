#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/cloud/nearest_grid.hpp"
#include "perception/cloud/point_cloud.hpp"
#include "perception/preprocessing/plane_removal.hpp"
#include "perception/recognition/object_database.hpp"

namespace uwscan::perception {

// How well a posed object model explains a scan segment, and what of the model the scan should
// have seen but did not: the verification stage of RecognizeObjects.

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

// A plane removed from the scan (the seabed, a wall) that an object rests on or stands against,
// oriented so that the sensor (at the origin) is on its positive side: n . x + offset_m > 0 there.
struct SupportPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit
  double offset_m = 0.0;
};

// What the scan saw around one segment: all its points (scan frame, planes too) and their index,
// the segment's window of directions, and over a grid of direction bins about `radius_m` wide
// at the segment covering that window, the scan points in each bin and the nearest depth of
// any of them.
struct SceneAround {
  SceneAround(const PointCloud& points, const KnnIndex& index, const Eigen::Vector3d& forward,
              double bin_rad);

  const PointCloud& points;
  const KnnIndex& index;
  SightAngles angles;
  double bin_rad = 0.0;
  Eigen::Vector2d lo, hi;  // the window: the segment's directions, widened by the margin and a bin
  long columns = 0, rows = 0;
  std::vector<double> nearest_depth;         // per bin, infinity where the scan has no point
  std::vector<std::uint32_t> bin_start;      // bin b's scan points are bin_points[bin_start[b] ..
  std::vector<std::uint32_t> bin_points;     // bin_start[b + 1]), indices into points
  std::vector<SupportPlane> support_planes;  // the caller's: planes seen around the segment

  // The bin of direction a, or -1 outside the window.
  long BinOf(const Eigen::Vector2d& a) const {
    if (!((a.array() >= lo.array()).all() && (a.array() <= hi.array()).all())) return -1;
    const long u = std::min(static_cast<long>((a.x() - lo.x()) / bin_rad), columns - 1);
    const long v = std::min(static_cast<long>((a.y() - lo.y()) / bin_rad), rows - 1);
    return v * columns + u;
  }
  // Some scan point lies more than `beyond_m` behind the plane through x normal to `normal`, on
  // a line of sight passing within `lateral_m` (at most a bin) of x: the sensor saw through a
  // surface there.
  bool SeenThrough(const Eigen::Vector3d& x, const Eigen::Vector3d& normal, double lateral_m,
                   double beyond_m) const;
};

// The scene around `segment`: `whole_scan` (with its k-d index `index`) over the segment's
// window of directions widened by `margin_m` at the segment, binned about `radius_m` wide there.
// Throws uwscan::Error on an empty segment or a non-finite point in it.
SceneAround SceneAroundSegment(const PointCloud& whole_scan, const KnnIndex& index,
                               const PointCloud& segment, double radius_m, double margin_m = 0.0);

// The planes of `planes` (removed from `scan`, their inliers indices into it) with at least
// `min_points` inliers within `radius_m` of `centre`: those an object there may rest on.
std::vector<SupportPlane> SupportPlanesAround(const PointCloud& scan,
                                              const std::vector<DetectedPlane>& planes,
                                              const Eigen::Vector3d& centre, double radius_m,
                                              std::size_t min_points);

// How a posed model meets the support planes around it.
struct SupportContact {
  // Share of its points more than the caller's depth beyond a plane, inside the seabed or a wall:
  // what the sensor cannot see there is not missing, but a solid object cannot be there either. A
  // pipe lying on the seabed fits a tee with its branch pointing down into it, or a flange with
  // the lower half of its rim in it, as well as it fits a pipe.
  double buried = 0.0;
  // Distance of its point nearest to a plane's far side, negative beyond it: about 0 for an
  // object resting on the seabed, a flange's neck 4.5 cm over the seabed its rim rests on.
  // Infinity without planes.
  double clearance_m = std::numeric_limits<double>::infinity();
};
SupportContact SupportContactOf(const ObjectModel& o, const Eigen::Isometry3d& T_S_O,
                                const std::vector<SupportPlane>& planes, double depth_m);

// Share of the posed model's surface the sensor should have seen where it saw past it instead.
// Should have seen: facing the sensor (not grazing), within the segment's window of directions
// (the sweep may have covered only part of the object), nearest to the sensor along its line of
// sight among the model's own points (a depth buffer over the scene's direction bins), so parts
// the object hides from itself are not expected, and not behind anything else the scan saw
// nearer in that direction (an object in front, a pipe lying across it). Of that surface, a model
// point is seen when a scan point lies within `radius_m` of it, and missing when a line of sight
// passes within half of `radius_m` of it and ends, on a scan point, more than that beyond the
// model's surface there (the sensor saw through where the model claims surface). Model points
// no line of sight came near, such as a handwheel's thin rim between two laser lines, or what a
// MEMS pattern did not light, are no evidence either way and count for neither: the former
// measure, no scan point near a point the sweep looked around, took those for missing and
// scored a handwheel in its true pose below the same wheel turned off it. Any scan point counts,
// not only the segment's: a valve's handle that occlusion cut off from its body into a segment
// of its own still shows that the handle is there, and the seabed points removed as a plane
// still show the object's lowest rim. 1 when nothing is expected.
double MissingShare(const ObjectModel& o, const Eigen::Isometry3d& T_S_O, const SceneAround& scene,
                    double radius_m);

// The counts MissingShare divides: model points the sensor should have seen and has evidence
// about (seen, or seen through), and of those the ones it saw through.
struct SurfaceEvidence {
  std::size_t expected = 0;
  std::size_t missing = 0;
};
SurfaceEvidence ExpectedSurface(const ObjectModel& o, const Eigen::Isometry3d& T_S_O,
                                const SceneAround& scene, double radius_m);

// Share of the segment (object frame) within `distance_m` of the model's surface: the
// point-to-plane distance to the nearest model point, when that point is within `reach_m` (about
// the model's sample spacing, so that a point beside a thin part, on the part's tangent plane but
// off its surface, does not count; at most model_grid's radius).
double CloseShare(const PointCloud& model, const NearestGrid& model_grid,
                  const PointCloud& segment_O, double distance_m, double reach_m);

}  // namespace uwscan::perception
