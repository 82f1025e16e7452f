#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace uwscan::perception {

// uwscan's one point-cloud type. Coordinates are stored in float relative to a local origin
// held in double, so clouds far from their frame's origin keep their precision (DESIGN.md).
// normals is either empty or holds one unit normal per point; so is intensity (a sensor's
// return strength, in the units of the file it came from; NaN where a point has none).
struct PointCloud {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // metres, in the cloud's frame
  std::vector<Eigen::Vector3f> points;               // metres, relative to origin
  std::vector<Eigen::Vector3f> normals;
  std::vector<float> intensity;

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool has_normals() const { return !normals.empty() && normals.size() == points.size(); }
  bool has_intensity() const { return !intensity.empty() && intensity.size() == points.size(); }
  // Absolute position of point i, in double.
  Eigen::Vector3d Point(std::size_t i) const { return origin + points[i].cast<double>(); }
};

// A cloud of the given absolute points, its origin at their centroid.
PointCloud MakeCloud(std::span<const Eigen::Vector3d> points);

// Throws uwscan::Error naming `what` when the cloud has fewer than `min_points` points, a
// non-finite point or normal, or a normals or intensity array of the wrong size.
void RequireValidCloud(const PointCloud& cloud, const std::string& what,
                       std::size_t min_points = 1);

// The cloud moved rigidly by T (points and normals; intensities kept); the origin moves, the float
// offsets only rotate, so no precision is lost to large translations.
PointCloud Transformed(const PointCloud& cloud, const Eigen::Isometry3d& T);

// Mean of the points, metres. Throws uwscan::Error for an empty cloud.
Eigen::Vector3d Centroid(const PointCloud& cloud);

// Axis-aligned bounding box diagonal, metres (0 for fewer than 2 points).
double BoundingBoxDiagonal(const PointCloud& cloud);

// Largest distance between two points, metres (0 below two points). Exact over an evenly
// strided subset of at most max_points points (all of them when the cloud is no larger), so
// it never exceeds the true diameter; O(max_points^2). Throws uwscan::Error when max_points < 2.
double Diameter(const PointCloud& cloud, std::size_t max_points = 4000);

// The subset of a cloud at the given indices (normals and intensities kept when present).
PointCloud Subset(const PointCloud& cloud, std::span<const std::size_t> indices);

}  // namespace uwscan::perception
