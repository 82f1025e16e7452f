#include "bench/recognition/real_pair_pcl.hpp"

#include <pcl/correspondence.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/features/shot_omp.h>
#include <pcl/filters/uniform_sampling.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>
#include <pcl/recognition/cg/geometric_consistency.h>
#include <pcl/registration/icp.h>

#include <cmath>
#include <vector>

#include "perception/cloud/pcl_conversion.hpp"

namespace uwscan::bench {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Normals = pcl::PointCloud<pcl::Normal>;
using Descriptors = pcl::PointCloud<pcl::SHOT352>;

Normals::Ptr NormalsOf(const Cloud::Ptr& cloud, int threads) {
  pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::Normal> estimation(threads);
  estimation.setKSearch(10);
  estimation.setInputCloud(cloud);
  auto normals = std::make_shared<Normals>();
  estimation.compute(*normals);
  return normals;
}

Cloud::Ptr Keypoints(const Cloud::Ptr& cloud, double radius_m) {
  pcl::UniformSampling<pcl::PointXYZ> sampling;
  sampling.setInputCloud(cloud);
  sampling.setRadiusSearch(radius_m);
  auto keypoints = std::make_shared<Cloud>();
  sampling.filter(*keypoints);
  return keypoints;
}

Descriptors::Ptr Shot(const Cloud::Ptr& keypoints, const Cloud::Ptr& cloud,
                      const Normals::Ptr& normals, int threads) {
  pcl::SHOTEstimationOMP<pcl::PointXYZ, pcl::Normal, pcl::SHOT352> shot(threads);
  shot.setRadiusSearch(0.02);
  shot.setInputCloud(keypoints);
  shot.setInputNormals(normals);
  shot.setSearchSurface(cloud);
  auto descriptors = std::make_shared<Descriptors>();
  shot.compute(*descriptors);
  return descriptors;
}

// Each scene descriptor with its nearest model descriptor, when near enough.
pcl::CorrespondencesPtr Match(const Descriptors::Ptr& model, const Descriptors::Ptr& scene) {
  pcl::KdTreeFLANN<pcl::SHOT352> tree;
  tree.setInputCloud(model);
  auto correspondences = std::make_shared<pcl::Correspondences>();
  std::vector<int> index(1);
  std::vector<float> squared(1);
  for (std::size_t i = 0; i < scene->size(); ++i) {
    if (!std::isfinite(scene->at(i).descriptor[0])) continue;  // SHOT leaves NaN where it fails
    if (tree.nearestKSearch(scene->at(i), 1, index, squared) == 1 && squared[0] < 0.25f) {
      correspondences->emplace_back(index[0], static_cast<int>(i), squared[0]);
    }
  }
  return correspondences;
}

}  // namespace

std::optional<Eigen::Isometry3d> PclCorrespondenceGrouping(const perception::PointCloud& model,
                                                           const perception::PointCloud& scene,
                                                           int threads) {
  // PCL's clouds hold each cloud's points relative to its own origin (centroid).
  const Cloud::Ptr model_cloud = perception::ToPclXYZ(model);
  const Cloud::Ptr scene_cloud = perception::ToPclXYZ(scene);
  const Normals::Ptr model_normals = NormalsOf(model_cloud, threads);
  const Normals::Ptr scene_normals = NormalsOf(scene_cloud, threads);
  const Cloud::Ptr model_keypoints = Keypoints(model_cloud, 0.01);
  const Cloud::Ptr scene_keypoints = Keypoints(scene_cloud, 0.03);
  const pcl::CorrespondencesPtr correspondences =
      Match(Shot(model_keypoints, model_cloud, model_normals, threads),
            Shot(scene_keypoints, scene_cloud, scene_normals, threads));

  pcl::GeometricConsistencyGrouping<pcl::PointXYZ, pcl::PointXYZ> grouping;
  grouping.setGCSize(0.01);
  grouping.setGCThreshold(5.0);
  grouping.setInputCloud(model_keypoints);
  grouping.setSceneCloud(scene_keypoints);
  grouping.setModelSceneCorrespondences(correspondences);
  std::vector<Eigen::Matrix4f, Eigen::aligned_allocator<Eigen::Matrix4f>> poses;
  std::vector<pcl::Correspondences> grouped;
  grouping.recognize(poses, grouped);
  if (poses.empty()) return std::nullopt;
  std::size_t best = 0;
  for (std::size_t i = 1; i < poses.size(); ++i) {
    if (grouped[i].size() > grouped[best].size()) best = i;
  }

  pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
  icp.setInputSource(model_cloud);
  icp.setInputTarget(scene_cloud);
  icp.setMaxCorrespondenceDistance(0.01);
  icp.setMaximumIterations(50);
  Cloud aligned;
  icp.align(aligned, poses[best]);
  if (!icp.hasConverged()) return std::nullopt;
  const Eigen::Isometry3d T_local(icp.getFinalTransformation().cast<double>());
  return Eigen::Translation3d(scene.origin) * T_local * Eigen::Translation3d(-model.origin);
}

}  // namespace uwscan::bench
