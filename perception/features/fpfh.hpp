#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <span>
#include <vector>

#include "perception/cloud/point_cloud.hpp"

namespace uwscan::perception {

// Fast Point Feature Histogram (Rusu et al. 2009): 33 bins (3 x 11).
using FpfhDescriptor = Eigen::Matrix<float, 33, 1>;

// Descriptors for a set of keypoints of a cloud.
struct FpfhFeatures {
  std::vector<std::size_t> indices;  // keypoint indices into the cloud they were computed on
  std::vector<FpfhDescriptor> descriptors;
};

struct FpfhOptions {
  double radius_m = 0.05;  // metres, support radius (neighbours strictly closer); > 0. Should
                           // exceed the radius the normals were estimated with.
  int threads = 0;         // OpenMP threads, 0 = OpenMP's default; the result does not depend on it

  // Throws uwscan::Error naming the field when it is out of range.
  void Check() const;
};

// FPFH (Rusu et al. 2009) at the keypoints, with every point of the cloud as the search surface,
// computed exactly as PCL's FPFHEstimation: for each point p of the keypoints' neighbourhoods a
// simplified point feature histogram SPFH(p) over its neighbours (three 11-bin histograms of
// the Darboux-frame angles, each summing to 100), then FPFH(q) = the SPFH of q's neighbours k
// (q and points coincident with it excluded) weighted by 1 / |q - k|^2 (PCL weights by the
// squared distance), each 11-bin third renormalised to sum to 100. As in PCL, a pair without a
// Darboux frame (coincident points, or the offset along the source normal) counts as angles
// (0, 0, 0). Bins agree with PCL's to float rounding of the sums.
// Keypoints whose descriptor is undefined (no neighbour within radius_m other than points
// coincident with the keypoint) are dropped: indices and descriptors stay aligned, in keypoint
// order. The cloud must carry
// unit normals (PointCloud::has_normals) and be finite; keypoints must be valid indices (both
// throw uwscan::Error otherwise, as does a cloud spanning more than 2^21 radii along an axis).
// No keypoints or an empty cloud give an empty result.
// Parallel with OpenMP; identical output for any thread count.
FpfhFeatures ComputeFpfh(const PointCloud& cloud_with_normals,
                         std::span<const std::size_t> keypoints, const FpfhOptions& options);

// The same descriptors through PCL's FPFHEstimationOMP (setSearchSurface on the whole cloud),
// with the same input checks and the same dropping of undefined descriptors: the reference
// ComputeFpfh is tested and benchmarked against.
FpfhFeatures ComputeFpfhPcl(const PointCloud& cloud_with_normals,
                            std::span<const std::size_t> keypoints, const FpfhOptions& options);

}  // namespace uwscan::perception
