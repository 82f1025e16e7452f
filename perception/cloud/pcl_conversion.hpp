#pragma once

// Conversions between uwscan's PointCloud and PCL's clouds. Include only from .cpp files: it
// pulls PCL headers. PCL clouds hold coordinates relative to the uwscan cloud's origin.

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "perception/cloud/point_cloud.hpp"

namespace uwscan::perception {

pcl::PointCloud<pcl::PointXYZ>::Ptr ToPclXYZ(const PointCloud& cloud);
// Normals must be present (has_normals()).
pcl::PointCloud<pcl::PointNormal>::Ptr ToPclPointNormal(const PointCloud& cloud);
pcl::PointCloud<pcl::Normal>::Ptr ToPclNormals(const PointCloud& cloud);

// A uwscan cloud from PCL points given relative to `origin`; normals copied when present.
PointCloud FromPcl(const pcl::PointCloud<pcl::PointXYZ>& pcl_cloud,
                   const Eigen::Vector3d& origin = Eigen::Vector3d::Zero());
PointCloud FromPcl(const pcl::PointCloud<pcl::PointNormal>& pcl_cloud,
                   const Eigen::Vector3d& origin = Eigen::Vector3d::Zero());

}  // namespace uwscan::perception
