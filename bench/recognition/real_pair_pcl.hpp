#pragma once

#include <Eigen/Geometry>
#include <optional>

#include "perception/cloud/point_cloud.hpp"

namespace uwscan::bench {

// PCL's correspondence grouping as its tutorial runs it on the milk carton pair: normals from
// the 10 nearest points, keypoints by uniform sampling (model 1 cm, scene 3 cm), SHOT
// descriptors over 2 cm, each scene descriptor matched to its nearest model descriptor (squared
// distance under 0.25), geometric consistency grouping (1 cm, at least 5 correspondences); the
// instance with most correspondences refined by PCL's ICP (1 cm, 50 iterations). The model's
// pose in the scene (both in their files' coordinates), or none when no instance is found.
std::optional<Eigen::Isometry3d> PclCorrespondenceGrouping(const perception::PointCloud& model,
                                                           const perception::PointCloud& scene,
                                                           int threads);

}  // namespace uwscan::bench
