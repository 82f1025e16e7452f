#include "perception/cloud/pcl_conversion.hpp"

#include "scanner/common/error.hpp"

namespace uwscan::perception {

pcl::PointCloud<pcl::PointXYZ>::Ptr ToPclXYZ(const PointCloud& cloud) {
  auto out = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  out->resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    (*out)[i].getVector3fMap() = cloud.points[i];
  }
  return out;
}

pcl::PointCloud<pcl::PointNormal>::Ptr ToPclPointNormal(const PointCloud& cloud) {
  if (!cloud.has_normals()) throw Error("ToPclPointNormal: the cloud has no normals");
  auto out = pcl::make_shared<pcl::PointCloud<pcl::PointNormal>>();
  out->resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    (*out)[i].getVector3fMap() = cloud.points[i];
    (*out)[i].getNormalVector3fMap() = cloud.normals[i];
  }
  return out;
}

pcl::PointCloud<pcl::Normal>::Ptr ToPclNormals(const PointCloud& cloud) {
  if (!cloud.has_normals()) throw Error("ToPclNormals: the cloud has no normals");
  auto out = pcl::make_shared<pcl::PointCloud<pcl::Normal>>();
  out->resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    (*out)[i].getNormalVector3fMap() = cloud.normals[i];
  }
  return out;
}

PointCloud FromPcl(const pcl::PointCloud<pcl::PointXYZ>& pcl_cloud, const Eigen::Vector3d& origin) {
  PointCloud out;
  out.origin = origin;
  out.points.reserve(pcl_cloud.size());
  for (const pcl::PointXYZ& p : pcl_cloud) out.points.push_back(p.getVector3fMap());
  return out;
}

PointCloud FromPcl(const pcl::PointCloud<pcl::PointNormal>& pcl_cloud,
                   const Eigen::Vector3d& origin) {
  PointCloud out;
  out.origin = origin;
  out.points.reserve(pcl_cloud.size());
  out.normals.reserve(pcl_cloud.size());
  for (const pcl::PointNormal& p : pcl_cloud) {
    out.points.push_back(p.getVector3fMap());
    out.normals.push_back(p.getNormalVector3fMap());
  }
  return out;
}

}  // namespace uwscan::perception
