#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "perception/cloud/point_cloud.hpp"

namespace uwscan::perception {

// Ensemble of Shape Functions (Wohlkinger & Vincze, "Ensemble of Shape Functions for 3D
// Object Classification", IEEE ROBIO 2011): one global 640-bin descriptor of a whole cloud,
// binned exactly as PCL 1.13's pcl::ESFEstimation bins it, so that the two agree:
//
//   bins   0- 63  A3 in      angles of sampled triangles, weighted by the voxel length of
//   bins  64-127  A3 out     the opposite side; in / out / mixed by line tracing
//   bins 128-191  A3 mixed
//   bins 192-255  D3 in      sqrt(triangle area), normalised by its maximum over the samples
//   bins 256-319  D3 out
//   bins 320-383  D3 mixed
//   bins 384-447  D2 in      point-pair distances, normalised by their maximum
//   bins 448-511  D2 out
//   bins 512-575  D2 mixed
//   bins 576-639  D2 ratio   fraction of occupied voxels along the mixed point pairs
//
// The cloud is centred on its centroid and scaled so that its farthest point lies at
// grid_size / 2 voxels; occupancy is the 3x3x3-dilated voxel grid of the points. A line
// between two points is "in" when (nearly) all voxels it crosses are occupied, "out" when at
// most 7 are, "mixed" otherwise. The sub-histograms are weighted as PCL weights them and the
// whole histogram sums to 1 (normalised).
using EsfDescriptor = Eigen::Matrix<float, 640, 1>;

struct EsfOptions {
  int samples = 20000;     // point triples drawn, 1..1e7 (each gives 3 D2, 1 D3 and 3 A3 values)
  std::uint64_t seed = 1;  // seed of the triple sampler (std::mt19937_64)
  // Voxels per side of the occupancy grid (even, 16..256). PCL uses 64, and its in/out voxel-count
  // thresholds, which are kept as they are, were tuned for 64.
  int grid_size = 64;
  // OpenMP threads binning the triples, 0 = OpenMP's default; the histogram does not depend on it
  // (integer counts).
  int threads = 0;
  // Throws uwscan::Error naming the offending field.
  void Check() const;
};

struct EsfResult {
  bool ok = false;
  std::string reason;                               // why ok is false (empty when ok)
  EsfDescriptor histogram = EsfDescriptor::Zero();  // sums to 1 when ok, zero otherwise
};

// ESF of the whole cloud (normals are ignored). Deterministic: the same cloud and options give
// the same histogram whatever the thread count (triangles are drawn in sequence, then traced in
// parallel with OpenMP into integer counts). The result depends only on the points relative
// to each other: exactly invariant to a change of the cloud's origin, invariant to translation
// and scale up to sampling noise (chi-square ~0.004 between seeds at 20000 samples). Rotation
// changes it beyond that noise because the occupancy grid is axis-aligned, as in PCL: a box
// turned off the axes moves by chi-square ~0.02-0.04 (a different shape: ~0.2 or more).
//
// Degenerate input is an error value (ok = false, reason set), never a throw or a hang: an
// empty cloud, fewer than 3 distinct points, a non-finite point or origin, all points
// collinear (every triangle thinner than PCL's area threshold), or a cloud where fewer than
// `samples` non-degenerate triangles turn up in 200 * samples random draws (for example a
// line plus one outlier). Throws uwscan::Error only for invalid options.
EsfResult ComputeEsf(const PointCloud& cloud, const EsfOptions& options = {});

// pcl::ESFEstimation<PointXYZ, ESFSignature640> on the same cloud, the reference for ComputeEsf.
// PCL reseeds the global rand() from the clock (time(nullptr)), so its output changes from one
// second to the next, and it loops forever when it cannot draw non-degenerate triangles. This
// wrapper only calls PCL on input where it terminates: the checks of ComputeEsf hold and at
// least 0.5 % of 4000 seeded trial triples pass PCL's triangle test; otherwise ok = false.
// Not thread-safe with other users of rand().
EsfResult ComputePclEsf(const PointCloud& cloud);

// Chi-square distance between two histograms of `size` bins:
//   sum over bins with a_i + b_i > 0 of (a_i - b_i)^2 / (a_i + b_i),
// accumulated in double; the same definition as flann::ChiSquareDistance. Bins are expected to
// be non-negative. For two normalised histograms (each summing to 1) it lies in [0, 2].
double ChiSquareDistance(const float* a, const float* b, int size);

}  // namespace uwscan::perception
