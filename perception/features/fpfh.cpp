#include "perception/features/fpfh.hpp"

#include <omp.h>
#include <pcl/features/fpfh_omp.h>

#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>

#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/cloud/pcl_conversion.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::perception {
namespace {

constexpr int kBins = 11;  // per angle feature; 3 features
constexpr std::uint32_t kNoRow = std::numeric_limits<std::uint32_t>::max();
using Histogram = std::array<float, 3 * kBins>;

void RequireFpfhInput(const PointCloud& cloud, std::span<const std::size_t> keypoints,
                      const std::string& what) {
  RequireValidCloud(cloud, what + ": cloud", 0);
  if (!keypoints.empty() && !cloud.has_normals()) {
    throw Error(what +
                ": the cloud has no normals (estimate them first: EstimateNormals, "
                "AttachNormals)");
  }
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    if (keypoints[i] >= cloud.size()) {
      throw Error(what + ": keypoint " + std::to_string(i) + " is index " +
                  std::to_string(keypoints[i]) + ", the cloud has " + std::to_string(cloud.size()) +
                  " points");
    }
  }
}

int ThreadCount(int threads) { return threads > 0 ? threads : omp_get_max_threads(); }

// PCL's test acos(|angle1|) > acos(|angle2|) (in float, as PCL's build calls acosf), deciding
// which point of a pair is the source. acos falls with slope of magnitude >= 1 and acosf is
// within one ulp (1.2e-7 on [0, pi/2]), so a gap above 4e-7 decides it without acosf; closer
// values call acosf exactly as PCL does, ties included.
inline bool SwapSourceAndTarget(float angle1, float angle2) {
  const float a1 = std::fabs(angle1), a2 = std::fabs(angle2);
  if (a1 <= 1.0f && a2 <= 1.0f) {  // beyond 1 (or NaN) acosf is NaN: PCL's test is false
    if (a1 + 4e-7f < a2) return true;
    if (a2 + 4e-7f < a1) return false;
  }
  return std::acos(a1) > std::acos(a2);
}

// The angle features (f1, f2, f3) of the pair (Rusu et al. 2009) of points 1 and 2, operation
// for operation as PCL's computePairFeatures (Vector4f with w = 0), so they agree to the bit.
// A pair without a Darboux frame (coincident points, or the offset along the source normal)
// gives (0, 0, 0): PCL's FPFHEstimation ignores computePairFeatures' failure and bins those
// zeros, and so do we.
inline Eigen::Vector3f PairFeatures(const Eigen::Vector4f& p1, const Eigen::Vector4f& n1,
                                    const Eigen::Vector4f& p2, const Eigen::Vector4f& n2) {
  Eigen::Vector4f dp2p1 = p2 - p1;
  const float f4 = dp2p1.norm();
  if (f4 == 0.0f) return Eigen::Vector3f::Zero();
  Eigen::Vector4f u = n1, n2_copy = n2;
  const float angle1 = u.dot(dp2p1) / f4;
  const float angle2 = n2_copy.dot(dp2p1) / f4;
  float f3;
  if (SwapSourceAndTarget(angle1, angle2)) {
    u = n2;
    n2_copy = n1;
    dp2p1 *= -1;
    f3 = -angle2;
  } else {
    f3 = angle1;
  }
  Eigen::Vector4f v = dp2p1.cross3(u);
  v[3] = 0.0f;
  const float v_norm = v.norm();
  if (v_norm == 0.0f) return Eigen::Vector3f::Zero();
  v /= v_norm;
  Eigen::Vector4f w = u.cross3(v);
  w[3] = 0.0f;
  return {std::atan2(w.dot(n2_copy), u.dot(n2_copy)), v.dot(n2_copy), f3};
}

// PCL's binning of the features: in double, with its float 1 / (2 pi), clamped to the range.
inline void Bins(const Eigen::Vector3f& f, int bins[3]) {
  constexpr float kInverseTwoPi = 1.0f / (2.0f * static_cast<float>(std::numbers::pi));
  const double x[3] = {
      (static_cast<double>(f[0]) + std::numbers::pi) * static_cast<double>(kInverseTwoPi),
      (static_cast<double>(f[1]) + 1.0) * 0.5, (static_cast<double>(f[2]) + 1.0) * 0.5};
  for (int i = 0; i < 3; ++i) {
    const int bin = static_cast<int>(std::floor(kBins * x[i]));
    bins[i] = bin < 0 ? 0 : (bin >= kBins ? kBins - 1 : bin);
  }
}

// The SPFH of point p over its neighbourhood (p itself included), as PCL: each other neighbour
// adds 100 / (neighbours - 1) to one bin of each feature.
Histogram Spfh(const std::vector<Eigen::Vector4f>& points,
               const std::vector<Eigen::Vector4f>& normals, std::uint32_t p,
               const std::vector<std::uint32_t>& neighbours) {
  Histogram h{};
  if (neighbours.size() < 2) return h;
  const float increment = 100.0f / static_cast<float>(neighbours.size() - 1);
  int bins[3];
  for (std::uint32_t q : neighbours) {
    if (q == p) continue;
    Bins(PairFeatures(points[p], normals[p], points[q], normals[q]), bins);
    h[static_cast<std::size_t>(bins[0])] += increment;
    h[static_cast<std::size_t>(kBins + bins[1])] += increment;
    h[static_cast<std::size_t>(2 * kBins + bins[2])] += increment;
  }
  return h;
}

// FPFH of a keypoint from its neighbours' SPFH weighted by 1 / squared distance (PCL's
// weightPointSPFHSignature, whose weighted values are float); accumulated in double where PCL
// sums the histogram in float, so ours carries no rounding of its own beyond the final cast.
// False when every weight or histogram is zero.
bool WeightSpfh(const std::vector<Histogram>& spfh, const std::vector<std::uint32_t>& row,
                const std::vector<std::uint32_t>& neighbours, const std::vector<float>& d2,
                FpfhDescriptor& descriptor) {
  Eigen::Matrix<double, 3 * kBins, 1> histogram = Eigen::Matrix<double, 3 * kBins, 1>::Zero();
  for (std::size_t i = 0; i < neighbours.size(); ++i) {
    if (d2[i] == 0.0f) continue;  // the keypoint itself and points on top of it
    const float weight = 1.0f / d2[i];
    const Histogram& h = spfh[row[neighbours[i]]];
    for (int b = 0; b < 3 * kBins; ++b) {
      histogram[b] += static_cast<double>(h[static_cast<std::size_t>(b)] * weight);
    }
  }
  const double sum[3] = {histogram.segment<kBins>(0).sum(), histogram.segment<kBins>(kBins).sum(),
                         histogram.segment<kBins>(2 * kBins).sum()};
  if (sum[0] == 0.0 && sum[1] == 0.0 && sum[2] == 0.0) return false;
  for (int b = 0; b < 3 * kBins; ++b) {
    const double total = sum[b / kBins];
    descriptor[b] = static_cast<float>(total != 0.0 ? histogram[b] * (100.0 / total) : 0.0);
  }
  return true;
}

}  // namespace

void FpfhOptions::Check() const {
  const OptionChecks check("FpfhOptions");
  check.Positive("radius_m", radius_m, "m");
  check.AtLeast("threads", threads, 0);
}

FpfhFeatures ComputeFpfh(const PointCloud& cloud_with_normals,
                         std::span<const std::size_t> keypoints, const FpfhOptions& options) {
  options.Check();
  const PointCloud& cloud = cloud_with_normals;
  RequireFpfhInput(cloud, keypoints, "ComputeFpfh");
  FpfhFeatures features;
  if (keypoints.empty()) return features;
  const int threads = ThreadCount(options.threads);
  const std::size_t n = cloud.size();
  const RadiusGrid grid(cloud.points, options.radius_m);
  const std::ptrdiff_t num_keypoints = static_cast<std::ptrdiff_t>(keypoints.size());

  // Points whose SPFH is needed: the neighbourhoods of the keypoints.
  std::vector<std::uint8_t> needed(n, 0);
#pragma omp parallel num_threads(threads)
  {
    std::vector<std::uint32_t> neighbours;
    std::vector<float> d2;
#pragma omp for schedule(dynamic, 64)
    for (std::ptrdiff_t k = 0; k < num_keypoints; ++k) {
      grid.Query(cloud.points[keypoints[static_cast<std::size_t>(k)]], neighbours, d2);
      for (std::uint32_t j : neighbours) {
        std::atomic_ref<std::uint8_t>(needed[j]).store(1, std::memory_order_relaxed);
      }
    }
  }
  std::vector<std::uint32_t> row(n, kNoRow);
  std::vector<std::uint32_t> spfh_points;
  for (std::size_t i = 0; i < n; ++i) {
    if (!needed[i]) continue;
    row[i] = static_cast<std::uint32_t>(spfh_points.size());
    spfh_points.push_back(static_cast<std::uint32_t>(i));
  }

  // Homogeneous copies (w = 0) for PCL's Vector4f arithmetic.
  std::vector<Eigen::Vector4f> points(n), normals(n);
  for (std::size_t i = 0; i < n; ++i) {
    points[i] << cloud.points[i], 0.0f;
    normals[i] << cloud.normals[i], 0.0f;
  }

  std::vector<Histogram> spfh(spfh_points.size());
  std::vector<FpfhDescriptor> descriptors(keypoints.size());
  std::vector<std::uint8_t> defined(keypoints.size(), 0);
#pragma omp parallel num_threads(threads)
  {
    std::vector<std::uint32_t> neighbours;
    std::vector<float> d2;
#pragma omp for schedule(dynamic, 64)
    for (std::ptrdiff_t r = 0; r < static_cast<std::ptrdiff_t>(spfh_points.size()); ++r) {
      const std::uint32_t p = spfh_points[static_cast<std::size_t>(r)];
      grid.Query(cloud.points[p], neighbours, d2);
      spfh[static_cast<std::size_t>(r)] = Spfh(points, normals, p, neighbours);
    }
    // The implicit barrier of the loop above orders the SPFH before their use.
#pragma omp for schedule(dynamic, 64)
    for (std::ptrdiff_t k = 0; k < num_keypoints; ++k) {
      const std::size_t kk = static_cast<std::size_t>(k);
      grid.Query(cloud.points[keypoints[kk]], neighbours, d2);
      defined[kk] = WeightSpfh(spfh, row, neighbours, d2, descriptors[kk]) ? 1 : 0;
    }
  }

  for (std::size_t k = 0; k < keypoints.size(); ++k) {
    if (!defined[k]) continue;
    features.indices.push_back(keypoints[k]);
    features.descriptors.push_back(descriptors[k]);
  }
  return features;
}

FpfhFeatures ComputeFpfhPcl(const PointCloud& cloud_with_normals,
                            std::span<const std::size_t> keypoints, const FpfhOptions& options) {
  options.Check();
  const PointCloud& cloud = cloud_with_normals;
  RequireFpfhInput(cloud, keypoints, "ComputeFpfhPcl");
  FpfhFeatures features;
  if (keypoints.empty()) return features;

  const pcl::PointCloud<pcl::PointXYZ>::Ptr surface = ToPclXYZ(cloud);
  const pcl::PointCloud<pcl::Normal>::Ptr normals = ToPclNormals(cloud);
  auto input = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  input->reserve(keypoints.size());
  for (std::size_t k : keypoints) input->push_back((*surface)[k]);
  pcl::FPFHEstimationOMP<pcl::PointXYZ, pcl::Normal, pcl::FPFHSignature33> estimation(
      static_cast<unsigned int>(ThreadCount(options.threads)));
  estimation.setInputCloud(input);
  estimation.setSearchSurface(surface);
  estimation.setInputNormals(normals);
  estimation.setRadiusSearch(options.radius_m);
  pcl::PointCloud<pcl::FPFHSignature33> output;
  estimation.compute(output);
  if (output.size() != keypoints.size()) {
    throw Error("ComputeFpfhPcl: PCL's FPFHEstimationOMP returned " +
                std::to_string(output.size()) + " descriptors for " +
                std::to_string(keypoints.size()) + " keypoints");
  }
  for (std::size_t k = 0; k < keypoints.size(); ++k) {
    const FpfhDescriptor descriptor = Eigen::Map<const FpfhDescriptor>(output[k].histogram);
    if (!descriptor.allFinite() || (descriptor.array() == 0.0f).all()) continue;
    features.indices.push_back(keypoints[k]);
    features.descriptors.push_back(descriptor);
  }
  return features;
}

}  // namespace uwscan::perception
