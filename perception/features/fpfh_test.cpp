#include "perception/features/fpfh.hpp"

#include <gtest/gtest.h>
#include <pcl/features/fpfh.h>

#include <cmath>
#include <limits>
#include <random>

#include "perception/cloud/pcl_conversion.hpp"
#include "perception/preprocessing/normals.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

// A wavy 0.6 m x 0.6 m sheet with a 0.1 m cube standing on it, noisy, with estimated normals:
// planar, curved and edge neighbourhoods, so every bin region gets used.
PointCloud MakeSurface(const Eigen::Vector3d& offset, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.0005);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  for (int n = 0; n < 6000; ++n) {
    const double x = 0.6 * u(rng) - 0.3, y = 0.6 * u(rng) - 0.3;
    points.emplace_back(x, y, 0.03 * std::sin(12.0 * x) * std::cos(9.0 * y) + noise(rng));
  }
  for (int n = 0; n < 2500; ++n) {
    const double a = 0.1 * u(rng) - 0.05, b = 0.1 * u(rng);
    const int face = n % 5;
    const Eigen::Vector3d p = face == 0   ? Eigen::Vector3d(a, 0.1 * u(rng) - 0.05, 0.13)
                              : face == 1 ? Eigen::Vector3d(-0.05, a, 0.03 + b)
                              : face == 2 ? Eigen::Vector3d(0.05, a, 0.03 + b)
                              : face == 3 ? Eigen::Vector3d(a, -0.05, 0.03 + b)
                                          : Eigen::Vector3d(a, 0.05, 0.03 + b);
    points.push_back(p + Eigen::Vector3d{noise(rng), noise(rng), noise(rng)});
  }
  for (Eigen::Vector3d& p : points) p += offset;
  const PointCloud cloud = MakeCloud(points);
  const NormalsResult normals =
      EstimateNormals(cloud, {.radius_m = 0.02, .viewpoint = offset + Eigen::Vector3d(0, 0, 2)});
  return AttachNormals(cloud, normals).cloud;
}

std::vector<std::size_t> EveryNth(std::size_t size, std::size_t step) {
  std::vector<std::size_t> indices;
  for (std::size_t i = 0; i < size; i += step) indices.push_back(i);
  return indices;
}

// PCL's single-threaded FPFHEstimation: the reference.
std::vector<FpfhDescriptor> PclFpfh(const PointCloud& cloud,
                                    const std::vector<std::size_t>& keypoints, double radius_m) {
  const auto surface = ToPclXYZ(cloud);
  auto input = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (std::size_t k : keypoints) input->push_back((*surface)[k]);
  pcl::FPFHEstimation<pcl::PointXYZ, pcl::Normal, pcl::FPFHSignature33> estimation;
  estimation.setInputCloud(input);
  estimation.setSearchSurface(surface);
  estimation.setInputNormals(ToPclNormals(cloud));
  estimation.setRadiusSearch(radius_m);
  pcl::PointCloud<pcl::FPFHSignature33> out;
  estimation.compute(out);
  std::vector<FpfhDescriptor> descriptors;
  for (const auto& d : out) descriptors.push_back(Eigen::Map<const FpfhDescriptor>(d.histogram));
  return descriptors;
}

TEST(ComputeFpfh, MatchesPclFpfhEstimationPerBin) {
  const PointCloud cloud = MakeSurface(Eigen::Vector3d(3.0, -2.0, 1.0), 1);
  const std::vector<std::size_t> keypoints = EveryNth(cloud.size(), 7);
  for (double radius : {0.025, 0.04}) {
    const FpfhFeatures ours = ComputeFpfh(cloud, keypoints, {.radius_m = radius});
    const std::vector<FpfhDescriptor> pcl = PclFpfh(cloud, keypoints, radius);
    ASSERT_EQ(ours.indices.size(), keypoints.size());  // every keypoint has neighbours here
    ASSERT_EQ(pcl.size(), keypoints.size());
    float worst = 0.0f;
    for (std::size_t k = 0; k < keypoints.size(); ++k) {
      EXPECT_EQ(ours.indices[k], keypoints[k]);
      worst = std::max(worst, (ours.descriptors[k] - pcl[k]).cwiseAbs().maxCoeff());
      for (int third = 0; third < 3; ++third) {
        EXPECT_NEAR(ours.descriptors[k].segment<11>(11 * third).sum(), 100.0f, 1e-3f);
      }
    }
    EXPECT_LE(worst, 1e-4f) << "radius " << radius;
  }
}

TEST(ComputeFpfh, MatchesPclOnExactGeometryWithTiedAngles) {
  // A noise-free cube sampled on a grid, each face with its exact normal: within a face both
  // pair angles are exactly 0, the tie that PCL settles with acosf.
  PointCloud cloud;
  for (int i = 0; i <= 20; ++i) {
    for (int j = 0; j <= 20; ++j) {
      const float a = 0.01f * i, b = 0.01f * j;
      const Eigen::Vector3f points[6] = {{a, b, 0},    {a, b, 0.2f}, {a, 0, b},
                                         {a, 0.2f, b}, {0, a, b},    {0.2f, a, b}};
      const Eigen::Vector3f normals[6] = {-Eigen::Vector3f::UnitZ(), Eigen::Vector3f::UnitZ(),
                                          -Eigen::Vector3f::UnitY(), Eigen::Vector3f::UnitY(),
                                          -Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitX()};
      for (int f = 0; f < 6; ++f) {
        cloud.points.push_back(points[f] - Eigen::Vector3f::Constant(0.1f));
        cloud.normals.push_back(normals[f]);
      }
    }
  }
  const std::vector<std::size_t> keypoints = EveryNth(cloud.size(), 5);
  const FpfhFeatures ours = ComputeFpfh(cloud, keypoints, {.radius_m = 0.035});
  const std::vector<FpfhDescriptor> pcl = PclFpfh(cloud, keypoints, 0.035);
  ASSERT_EQ(ours.indices.size(), keypoints.size());
  for (std::size_t k = 0; k < keypoints.size(); ++k) {
    EXPECT_LE((ours.descriptors[k] - pcl[k]).cwiseAbs().maxCoeff(), 1e-4f) << k;
  }
}

TEST(ComputeFpfh, PclReferencePathAgrees) {
  const PointCloud cloud = MakeSurface(Eigen::Vector3d::Zero(), 2);
  const std::vector<std::size_t> keypoints = EveryNth(cloud.size(), 11);
  const FpfhFeatures ours = ComputeFpfh(cloud, keypoints, {.radius_m = 0.03});
  const FpfhFeatures pcl = ComputeFpfhPcl(cloud, keypoints, {.radius_m = 0.03, .threads = 2});
  ASSERT_EQ(ours.indices, pcl.indices);
  for (std::size_t k = 0; k < ours.indices.size(); ++k) {
    EXPECT_LE((ours.descriptors[k] - pcl.descriptors[k]).cwiseAbs().maxCoeff(), 1e-4f);
  }
}

TEST(ComputeFpfh, IdenticalWithOneAndTwoThreads) {
  const PointCloud cloud = MakeSurface(Eigen::Vector3d::Zero(), 3);
  const std::vector<std::size_t> keypoints = EveryNth(cloud.size(), 3);
  const FpfhFeatures a = ComputeFpfh(cloud, keypoints, {.radius_m = 0.03, .threads = 1});
  const FpfhFeatures b = ComputeFpfh(cloud, keypoints, {.radius_m = 0.03, .threads = 2});
  EXPECT_EQ(a.indices, b.indices);
  ASSERT_EQ(a.descriptors.size(), b.descriptors.size());
  for (std::size_t k = 0; k < a.descriptors.size(); ++k) {
    EXPECT_EQ(a.descriptors[k], b.descriptors[k]);
  }
}

TEST(ComputeFpfh, InvariantToTheCloudsOrigin) {
  const PointCloud cloud = MakeSurface(Eigen::Vector3d::Zero(), 4);
  PointCloud far = cloud;
  far.origin += Eigen::Vector3d(2e6, 1e6, -3e5);
  const std::vector<std::size_t> keypoints = EveryNth(cloud.size(), 10);
  const FpfhFeatures a = ComputeFpfh(cloud, keypoints, {.radius_m = 0.03});
  const FpfhFeatures b = ComputeFpfh(far, keypoints, {.radius_m = 0.03});
  EXPECT_EQ(a.indices, b.indices);
  for (std::size_t k = 0; k < a.descriptors.size(); ++k) {
    EXPECT_EQ(a.descriptors[k], b.descriptors[k]);
  }
}

TEST(ComputeFpfh, DropsKeypointsWithoutNeighbours) {
  PointCloud cloud = MakeSurface(Eigen::Vector3d::Zero(), 5);
  // An isolated point far from the surface, and a pair of coincident points.
  cloud.points.push_back(Eigen::Vector3f(5, 5, 5));
  cloud.normals.push_back(Eigen::Vector3f::UnitZ());
  cloud.points.push_back(Eigen::Vector3f(-5, 5, 5));
  cloud.normals.push_back(Eigen::Vector3f::UnitZ());
  cloud.points.push_back(Eigen::Vector3f(-5, 5, 5));
  cloud.normals.push_back(Eigen::Vector3f::UnitX());
  const std::size_t n = cloud.size();
  const std::vector<std::size_t> keypoints = {0, n - 3, 1, n - 2, n - 1, 2};
  const FpfhFeatures ours = ComputeFpfh(cloud, keypoints, {.radius_m = 0.03});
  EXPECT_EQ(ours.indices, (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_EQ(ours.descriptors.size(), 3u);
  const FpfhFeatures pcl = ComputeFpfhPcl(cloud, keypoints, {.radius_m = 0.03});
  EXPECT_EQ(pcl.indices, ours.indices);
}

TEST(ComputeFpfh, EmptyTinyCollinearAndBadInput) {
  const FpfhOptions options{.radius_m = 0.05};
  EXPECT_TRUE(ComputeFpfh(PointCloud{}, {}, options).indices.empty());
  PointCloud cloud = MakeSurface(Eigen::Vector3d::Zero(), 6);
  EXPECT_TRUE(ComputeFpfh(cloud, {}, options).indices.empty());

  // One point: no neighbour, no descriptor.
  PointCloud one;
  one.points = {Eigen::Vector3f::Zero()};
  one.normals = {Eigen::Vector3f::UnitZ()};
  const std::vector<std::size_t> first = {0};
  EXPECT_TRUE(ComputeFpfh(one, first, options).indices.empty());

  // Collinear points with normals along the line: no pair has a Darboux frame, and as in PCL
  // every pair counts as angles (0, 0, 0), the middle bins.
  PointCloud line;
  for (int i = 0; i < 20; ++i) {
    line.points.push_back(Eigen::Vector3f(0.01f * i, 0, 0));
    line.normals.push_back(Eigen::Vector3f::UnitX());
  }
  const std::vector<std::size_t> all = EveryNth(line.size(), 1);
  const FpfhFeatures collinear = ComputeFpfh(line, all, options);
  ASSERT_EQ(collinear.indices.size(), line.size());
  for (const FpfhDescriptor& d : collinear.descriptors) {
    EXPECT_FLOAT_EQ(d[5], 100.0f);
    EXPECT_FLOAT_EQ(d[16], 100.0f);
    EXPECT_FLOAT_EQ(d[27], 100.0f);
  }
  const std::vector<FpfhDescriptor> pcl_collinear = PclFpfh(line, all, options.radius_m);
  for (std::size_t k = 0; k < all.size(); ++k) {
    EXPECT_LE((collinear.descriptors[k] - pcl_collinear[k]).cwiseAbs().maxCoeff(), 1e-4f);
  }

  const std::vector<std::size_t> beyond = {cloud.size()};
  EXPECT_THROW(ComputeFpfh(cloud, beyond, options), Error);
  EXPECT_THROW(ComputeFpfh(cloud, first, {.radius_m = 0.0}), Error);
  EXPECT_THROW(ComputeFpfh(cloud, first, {.radius_m = 0.05, .threads = -1}), Error);
  PointCloud bare = cloud;
  bare.normals.clear();
  EXPECT_THROW(ComputeFpfh(bare, first, options), Error);
  EXPECT_THROW(ComputeFpfhPcl(bare, first, options), Error);
  cloud.normals[4].x() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(ComputeFpfh(cloud, first, options), Error);
}

}  // namespace
}  // namespace uwscan::perception
