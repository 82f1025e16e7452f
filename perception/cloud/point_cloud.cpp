#include "perception/cloud/point_cloud.hpp"

#include <cmath>

#include "scanner/common/error.hpp"

namespace uwscan::perception {

PointCloud MakeCloud(std::span<const Eigen::Vector3d> points) {
  PointCloud cloud;
  if (points.empty()) return cloud;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  cloud.origin = centroid.allFinite() ? centroid : Eigen::Vector3d::Zero();
  cloud.points.reserve(points.size());
  for (const Eigen::Vector3d& p : points) cloud.points.push_back((p - cloud.origin).cast<float>());
  return cloud;
}

void RequireValidCloud(const PointCloud& cloud, const std::string& what, std::size_t min_points) {
  if (cloud.size() < min_points) {
    throw Error(what + ": needs at least " + std::to_string(min_points) + " points, has " +
                std::to_string(cloud.size()));
  }
  if (!cloud.origin.allFinite()) throw Error(what + ": origin is not finite");
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.points[i].allFinite()) {
      throw Error(what + ": point " + std::to_string(i) + " is not finite (NaN or inf)");
    }
  }
  if (!cloud.normals.empty()) {
    if (cloud.normals.size() != cloud.size()) {
      throw Error(what + ": has " + std::to_string(cloud.normals.size()) + " normals for " +
                  std::to_string(cloud.size()) + " points");
    }
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      if (!cloud.normals[i].allFinite()) {
        throw Error(what + ": normal " + std::to_string(i) + " is not finite");
      }
    }
  }
  if (!cloud.intensity.empty() && cloud.intensity.size() != cloud.size()) {
    throw Error(what + ": has " + std::to_string(cloud.intensity.size()) + " intensities for " +
                std::to_string(cloud.size()) + " points");
  }
}

PointCloud Transformed(const PointCloud& cloud, const Eigen::Isometry3d& T) {
  PointCloud out;
  out.origin = T * cloud.origin;
  const Eigen::Matrix3f R = T.linear().cast<float>();
  out.points.reserve(cloud.size());
  for (const Eigen::Vector3f& p : cloud.points) out.points.push_back(R * p);
  out.normals.reserve(cloud.normals.size());
  for (const Eigen::Vector3f& n : cloud.normals) out.normals.push_back(R * n);
  out.intensity = cloud.intensity;
  return out;
}

double Diameter(const PointCloud& cloud, std::size_t max_points) {
  if (max_points < 2) throw Error("Diameter: max_points must be >= 2");
  const std::size_t stride = std::max<std::size_t>(1, (cloud.size() + max_points - 1) / max_points);
  float best = 0.0f;
  for (std::size_t i = 0; i < cloud.size(); i += stride) {
    for (std::size_t j = i + stride; j < cloud.size(); j += stride) {
      best = std::max(best, (cloud.points[i] - cloud.points[j]).squaredNorm());
    }
  }
  return std::sqrt(static_cast<double>(best));
}

Eigen::Vector3d Centroid(const PointCloud& cloud) {
  if (cloud.empty()) throw Error("Centroid: the cloud is empty");
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < cloud.size(); ++i) sum += cloud.Point(i);
  return sum / static_cast<double>(cloud.size());
}

double BoundingBoxDiagonal(const PointCloud& cloud) {
  if (cloud.size() < 2) return 0.0;
  Eigen::Vector3f lo = cloud.points.front(), hi = cloud.points.front();
  for (const Eigen::Vector3f& p : cloud.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return static_cast<double>((hi - lo).norm());
}

PointCloud Subset(const PointCloud& cloud, std::span<const std::size_t> indices) {
  PointCloud out;
  out.origin = cloud.origin;
  out.points.reserve(indices.size());
  for (std::size_t i : indices) out.points.push_back(cloud.points.at(i));
  if (cloud.has_normals()) {
    out.normals.reserve(indices.size());
    for (std::size_t i : indices) out.normals.push_back(cloud.normals[i]);
  }
  if (cloud.has_intensity()) {
    out.intensity.reserve(indices.size());
    for (std::size_t i : indices) out.intensity.push_back(cloud.intensity[i]);
  }
  return out;
}

}  // namespace uwscan::perception
