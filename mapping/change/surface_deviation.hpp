#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "perception/cloud/point_cloud.hpp"

namespace uwscan::mapping {

// Signed distances between two surfaces along the reference's local normals, with a level of
// detection, after M3C2 (Lague et al. 2013): at each core point, the points of either cloud
// within a cylinder about the normal are projected on it and averaged; the distance is the
// difference of the two means. The level of detection is what the two means' and the
// placements' uncertainties allow at the stated confidence (M3C2-EP, Winiwarter et al. 2021,
// with the placement's covariance from the caller).
struct DeviationOptions {
  double core_spacing_m = 0.01;      // core points: the reference voxelised at this size, > 0
  double normal_radius_m = 0.025;    // normals from the reference's points within this radius, > 0
  double cylinder_radius_m = 0.015;  // points averaged within this distance of the normal line, > 0
  double max_depth_m = 0.1;          // ... and within this distance of the core point along it, > 0
  // Along the normal, points more than this apart belong to different surfaces (the near and
  // far walls of a pipe, a flange behind a pipe); each cloud's surface nearest the core point
  // is taken. Metres, > 0.
  double surface_gap_m = 0.01;
  // Where a cloud has normals, only its points whose normal lies within this angle of the core
  // point's (either way) are averaged: the sides of a crate or a pipe, seen at a slant, are not
  // mixed into the seabed beside them. Radians, in [0, pi/2].
  double max_normal_angle_rad = 0.5;
  int min_points = 3;  // fewer points of the map in the cylinder: not inspected, >= 2
  // Standard deviation along the normal of one point of each cloud, at least (metres, >= 0): a
  // floor under the spread measured in the cylinder, which a few points underestimate.
  double map_point_sigma_m = 0.0005;
  double reference_point_sigma_m = 0.0005;  // 0 for a design model
  // Slowly varying offsets left by the surveys' placement errors are taken out within this
  // radius (RemoveLocalOffsets; metres, >= 0, 0 = off): changes up to about this size across
  // keep their depth.
  double local_offset_radius_m = 0.2;
  // Core points with an edge of the inspected surface within about 0.6 times this radius (a
  // swath's end, a shadow) have their own spread of deviations (AtSurfaceEdge), metres, > 0.
  double edge_radius_m = 0.05;
  double confidence = 0.95;  // two-sided, of the level of detection, in (0, 1)
  int threads = 0;  // OpenMP threads, 0 = OpenMP's default; the result does not depend on it
  void Check() const;
};

enum class SurfaceStatus : std::uint8_t {
  kNotInspected,  // the map has no surface here (never seen, or moved beyond max_depth_m)
  kUnchanged,     // |deviation| within the level of detection
  kChanged        // |deviation| beyond it: significant
};

struct CoreDeviation {
  Eigen::Vector3d point_W = Eigen::Vector3d::Zero();    // on the reference
  Eigen::Vector3d normal_W = Eigen::Vector3d::UnitZ();  // the reference's normal, unit
  // Map surface minus reference surface along the normal, metres: > 0 where the map lies in
  // front of the reference (material gained), < 0 behind it (lost). NaN when not inspected.
  double deviation_m = std::numeric_limits<double>::quiet_NaN();
  double lod_m = std::numeric_limits<double>::quiet_NaN();  // level of detection, metres
  int map_points = 0, reference_points = 0;
  SurfaceStatus status = SurfaceStatus::kNotInspected;
};

// Core points of the reference with their unit normals; where the reference's points there do
// not define a plane the core point is left out. `orient(point, normal)` returns the normal
// flipped as the caller wants it (towards the outside, or the sensor).
struct CorePoints {
  std::vector<Eigen::Vector3d> points_W, normals_W;
  // Per core point, whether the map's sensor could have seen it (empty: all): a design model's
  // faces turned away from every pose (a pipe's bore, the underside of a valve wheel's spokes)
  // are reported not inspected instead of being matched to the surface in front of them.
  std::vector<char> visible;
};
CorePoints MakeCorePoints(
    const perception::PointCloud& reference, const DeviationOptions& options,
    const std::function<Eigen::Vector3d(const Eigen::Vector3d&, const Eigen::Vector3d&)>& orient);

// The deviation at each core point between `map` (already aligned on the reference) and
// `reference`. `placement_sigma(core point, normal)` is the standard deviation along the
// normal (metres) of where the two surfaces were placed: poses, alignment; it adds to the
// level of detection. Throws uwscan::Error on invalid options or an empty cloud.
std::vector<CoreDeviation> MeasureDeviations(
    const perception::PointCloud& map, const perception::PointCloud& reference,
    const CorePoints& core, const DeviationOptions& options,
    const std::function<double(const Eigen::Vector3d&, const Eigen::Vector3d&)>& placement_sigma);

// The two-sided standard normal quantile: z with P(|N(0,1)| <= z) = confidence.
double TwoSidedQuantile(double confidence);

}  // namespace uwscan::mapping
