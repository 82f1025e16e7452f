#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <span>
#include <vector>

#include "perception/point_cloud.hpp"

namespace uwscan::perception {

// Fast Point Feature Histogram (Rusu et al. 2009): 33 bins (3 x 11).
using FpfhDescriptor = Eigen::Matrix<float, 33, 1>;

// Descriptors for a set of keypoints of a cloud.
struct FpfhFeatures {
  std::vector<std::size_t> indices;  // keypoint indices into the cloud they were computed on
  std::vector<FpfhDescriptor> descriptors;
};

}  // namespace uwscan::perception
