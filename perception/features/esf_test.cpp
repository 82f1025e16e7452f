#include "perception/features/esf.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <iostream>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "perception/cloud/point_cloud.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

constexpr double kPi = std::numbers::pi;

enum class Shape { kSphere, kBox, kCylinder, kPlanePatch };
const std::vector<Shape> kShapes = {Shape::kSphere, Shape::kBox, Shape::kCylinder,
                                    Shape::kPlanePatch};

const char* Name(Shape shape) {
  switch (shape) {
    case Shape::kSphere:
      return "sphere";
    case Shape::kBox:
      return "box";
    case Shape::kCylinder:
      return "cylinder";
    case Shape::kPlanePatch:
      return "plane patch";
  }
  return "?";
}

// n points uniformly over the surface of a shape of about 0.2-0.4 m, in absolute coordinates
// around `center`.
std::vector<Eigen::Vector3d> SampleShape(Shape shape, int n, std::uint64_t seed,
                                         const Eigen::Vector3d& center = Eigen::Vector3d::Zero()) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    switch (shape) {
      case Shape::kSphere: {  // radius 0.15 m
        p = 0.15 * Eigen::Vector3d{g(rng), g(rng), g(rng)}.normalized();
        break;
      }
      case Shape::kBox: {  // 0.4 x 0.25 x 0.1 m, faces chosen by area
        const Eigen::Vector3d size(0.4, 0.25, 0.1);
        const Eigen::Vector3d areas(size.y() * size.z(), size.x() * size.z(), size.x() * size.y());
        const double pick = u(rng) * areas.sum();
        const int axis = pick < areas.x() ? 0 : (pick < areas.x() + areas.y() ? 1 : 2);
        p = Eigen::Vector3d{u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5}.cwiseProduct(size);
        p[axis] = (u(rng) < 0.5 ? -0.5 : 0.5) * size[axis];
        break;
      }
      case Shape::kCylinder: {  // radius 0.08 m, height 0.3 m, with caps, chosen by area
        const double r = 0.08, h = 0.3;
        const double side = 2 * kPi * r * h, caps = 2 * kPi * r * r;
        const double phi = 2 * kPi * u(rng);
        if (u(rng) * (side + caps) < side) {
          p = Eigen::Vector3d(r * std::cos(phi), r * std::sin(phi), h * (u(rng) - 0.5));
        } else {
          const double rho = r * std::sqrt(u(rng));
          p = Eigen::Vector3d(rho * std::cos(phi), rho * std::sin(phi),
                              (u(rng) < 0.5 ? -0.5 : 0.5) * h);
        }
        break;
      }
      case Shape::kPlanePatch: {  // 0.4 x 0.3 m
        p = Eigen::Vector3d{0.4 * (u(rng) - 0.5), 0.3 * (u(rng) - 0.5), 0.0};
        break;
      }
    }
    points.push_back(center + p);
  }
  return points;
}

PointCloud ShapeCloud(Shape shape, int n, std::uint64_t seed) {
  return MakeCloud(SampleShape(shape, n, seed));
}

double Chi2(const EsfDescriptor& a, const EsfDescriptor& b) {
  return ChiSquareDistance(a.data(), b.data(), static_cast<int>(a.size()));
}

EsfDescriptor Esf(const PointCloud& cloud, std::uint64_t seed = 1) {
  EsfOptions options;
  options.seed = seed;
  const EsfResult r = ComputeEsf(cloud, options);
  EXPECT_TRUE(r.ok) << r.reason;
  return r.histogram;
}

// Blocks until time(nullptr) has moved on, so that PCL's srand(time) gives a new sequence.
void WaitForNextSecond() {
  const std::time_t start = std::time(nullptr);
  while (std::time(nullptr) == start) std::this_thread::sleep_for(std::chrono::milliseconds(20));
}

TEST(EsfTest, HistogramIsNormalisedAndNonNegative) {
  const EsfResult r = ComputeEsf(ShapeCloud(Shape::kBox, 2000, 3));
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_TRUE(r.reason.empty());
  EXPECT_NEAR(r.histogram.cast<double>().sum(), 1.0, 1e-5);
  EXPECT_GE(r.histogram.minCoeff(), 0.0f);
  // Every group of bins gets something on a box (lines in, out and mixed).
  for (int group = 0; group < 10; ++group) {
    EXPECT_GT(r.histogram.segment<64>(64 * group).sum(), 0.0f) << "group " << group;
  }
}

TEST(EsfTest, DeterministicForASeedAndCloseAcrossSeeds) {
  const PointCloud cloud = ShapeCloud(Shape::kCylinder, 3000, 4);
  const EsfDescriptor a = Esf(cloud, 7);
  const EsfDescriptor b = Esf(cloud, 7);
  EXPECT_TRUE(a == b) << "same seed, different histogram";
  const EsfDescriptor c = Esf(cloud, 8);
  EXPECT_FALSE(a == c);
  const double d = Chi2(a, c);
  std::cout << "[ESF] ours seed 7 vs seed 8 (cylinder, 3000 points): chi2 = " << d << "\n";
  EXPECT_LT(d, 0.05);
}

TEST(EsfTest, IdenticalForOneAndTwoThreads) {
  const PointCloud cloud = ShapeCloud(Shape::kSphere, 3000, 5);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const EsfDescriptor one = Esf(cloud, 3);
  omp_set_num_threads(2);
  const EsfDescriptor two = Esf(cloud, 3);
  omp_set_num_threads(threads);
  EXPECT_TRUE(one == two);
  // The same through EsfOptions::threads, whatever OpenMP's default.
  EsfOptions options;
  options.seed = 3;
  options.threads = 1;
  const EsfResult by_option_one = ComputeEsf(cloud, options);
  options.threads = 2;
  const EsfResult by_option_two = ComputeEsf(cloud, options);
  ASSERT_TRUE(by_option_one.ok && by_option_two.ok);
  EXPECT_TRUE(by_option_one.histogram == one);
  EXPECT_TRUE(by_option_two.histogram == one);
}

TEST(EsfTest, ThreeDistinctPointsAreEnough) {
  const std::vector<Eigen::Vector3d> points = {{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}, {0, 0, 0}};
  const EsfResult r = ComputeEsf(MakeCloud(points));
  EXPECT_TRUE(r.ok) << r.reason;
}

// Ours and PCL's draw different triangles, so they differ by sampling noise at least. The
// noise floor is the distance between two PCL runs (a second apart: PCL seeds rand() with
// time(nullptr)); ours must stay within a small factor of it. The ratio of two such chi-square
// distances scatters (97th percentile about 1.5 for one shape, measured with our sampler), so
// the tight bound is on the sum over the shapes and each shape gets a loose one.
TEST(EsfTest, AgreesWithPclOnShapes) {
  std::vector<PointCloud> clouds;
  for (Shape shape : kShapes) clouds.push_back(ShapeCloud(shape, 3000, 11));
  std::vector<EsfResult> pcl_a, pcl_b;
  for (const PointCloud& cloud : clouds) pcl_a.push_back(ComputePclEsf(cloud));
  WaitForNextSecond();
  for (const PointCloud& cloud : clouds) pcl_b.push_back(ComputePclEsf(cloud));
  double floor_sum = 0.0, to_pcl_sum = 0.0;
  for (std::size_t s = 0; s < kShapes.size(); ++s) {
    ASSERT_TRUE(pcl_a[s].ok) << pcl_a[s].reason;
    ASSERT_TRUE(pcl_b[s].ok) << pcl_b[s].reason;
    const EsfDescriptor ours = Esf(clouds[s]);
    const double floor = Chi2(pcl_a[s].histogram, pcl_b[s].histogram);
    const double to_pcl = 0.5 * (Chi2(ours, pcl_a[s].histogram) + Chi2(ours, pcl_b[s].histogram));
    std::cout << "[ESF] " << Name(kShapes[s]) << ": chi2 ours-vs-PCL = " << to_pcl
              << ", PCL-vs-PCL = " << floor << " (ratio " << to_pcl / floor << ")\n";
    EXPECT_GT(floor, 0.0) << "PCL gave the same histogram twice";
    EXPECT_LT(to_pcl, 3.0 * floor) << Name(kShapes[s]);
    floor_sum += floor;
    to_pcl_sum += to_pcl;
  }
  std::cout << "[ESF] all shapes: ours-vs-PCL / PCL-vs-PCL = " << to_pcl_sum / floor_sum << "\n";
  EXPECT_LT(to_pcl_sum, 1.5 * floor_sum);
}

TEST(EsfTest, InvariantToHugeTranslation) {
  const std::vector<Eigen::Vector3d> points = SampleShape(Shape::kBox, 3000, 12);
  const PointCloud cloud = MakeCloud(points);
  const EsfDescriptor reference = Esf(cloud, 1);
  const double noise = Chi2(reference, Esf(cloud, 2));

  // Moving the origin 1e6 m leaves the float offsets, and so the histogram, unchanged.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(1e6, -2e6, 3e5);
  EXPECT_TRUE(Esf(Transformed(cloud, T), 1) == reference);

  // Absolute coordinates 1e6 m away: MakeCloud keeps them in double through the origin.
  std::vector<Eigen::Vector3d> far_points;
  for (const Eigen::Vector3d& p : points) far_points.push_back(p + Eigen::Vector3d(1e6, 1e6, -1e6));
  const double translated = Chi2(reference, Esf(MakeCloud(far_points), 1));
  std::cout << "[ESF] box: seed-to-seed chi2 " << noise << ", 1e6 m translation " << translated
            << "\n";
  EXPECT_LT(translated, 0.1 * noise);
}

// ESF voxelises on an axis-aligned grid, so it is rotation invariant only up to how the grid
// cuts the shape: within sampling noise for a sphere, but a box turned off its axes moves by
// several times the noise, for PCL as for us. Same seed, so the same triangles are drawn.
TEST(EsfTest, RotationChangesItNoMoreThanPcls) {
  std::mt19937_64 rng(13);
  std::normal_distribution<double> g(0.0, 1.0);
  for (Shape shape : {Shape::kSphere, Shape::kBox, Shape::kCylinder}) {
    const PointCloud cloud = ShapeCloud(shape, 3000, 14);
    const EsfDescriptor reference = Esf(cloud, 1);
    const double noise = Chi2(reference, Esf(cloud, 2));
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond{g(rng), g(rng), g(rng), g(rng)}.normalized().toRotationMatrix();
    T.translation() = Eigen::Vector3d(1e6, 2e6, -5e5);
    const PointCloud moved = Transformed(cloud, T);
    const double ours = Chi2(reference, Esf(moved, 1));
    // Two PCL calls in the same second draw the same triangles too (a second apart they add
    // sampling noise, which only loosens the bound).
    const EsfResult pcl_reference = ComputePclEsf(cloud);
    const EsfResult pcl_moved = ComputePclEsf(moved);
    ASSERT_TRUE(pcl_reference.ok && pcl_moved.ok);
    const double pcl = Chi2(pcl_reference.histogram, pcl_moved.histogram);
    std::cout << "[ESF] " << Name(shape) << " rotated: chi2 ours " << ours << ", PCL " << pcl
              << "; seed-to-seed noise " << noise << "\n";
    EXPECT_LT(ours, 1.5 * pcl + noise) << Name(shape);
    if (shape == Shape::kSphere) {
      EXPECT_LT(ours, noise);
    }
  }
}

TEST(EsfTest, DifferentShapesAreFartherApartThanResamplings) {
  std::vector<EsfDescriptor> first, second;
  for (Shape shape : kShapes) {
    first.push_back(Esf(ShapeCloud(shape, 2500, 21), 1));
    second.push_back(Esf(ShapeCloud(shape, 2500, 22), 2));
  }
  double worst_same = 0.0;
  double closest_different = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < kShapes.size(); ++i) {
    worst_same = std::max(worst_same, Chi2(first[i], second[i]));
    for (std::size_t j = 0; j < kShapes.size(); ++j) {
      if (i != j) closest_different = std::min(closest_different, Chi2(first[i], second[j]));
    }
  }
  std::cout << "[ESF] same shape resampled: max chi2 " << worst_same
            << "; different shapes: min chi2 " << closest_different << "\n";
  EXPECT_GT(closest_different, 3.0 * worst_same);
}

struct DegenerateCase {
  std::string name;
  PointCloud cloud;
};

std::vector<DegenerateCase> DegenerateClouds() {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<DegenerateCase> cases;
  cases.push_back({"empty", PointCloud{}});
  cases.push_back({"one point", MakeCloud(std::vector<Eigen::Vector3d>{{1, 2, 3}})});
  cases.push_back({"two points", MakeCloud(std::vector<Eigen::Vector3d>{{1, 2, 3}, {1, 2, 4}})});
  {
    std::vector<Eigen::Vector3d> same(1000, Eigen::Vector3d(5, 6, 7));
    cases.push_back({"1000 identical points", MakeCloud(same)});
  }
  {
    std::vector<Eigen::Vector3d> two;
    for (int i = 0; i < 1000; ++i)
      two.push_back(i % 2 ? Eigen::Vector3d(0, 0, 0) : Eigen::Vector3d(1, 1, 1));
    cases.push_back({"1000 points at 2 places", MakeCloud(two)});
  }
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 5000; ++i)
    line.push_back(Eigen::Vector3d(1, -2, 0.5) * (0.001 * i) + Eigen::Vector3d(1e5, 0, 0));
  cases.push_back({"5000 collinear points", MakeCloud(line)});
  line.push_back(Eigen::Vector3d(1e5 + 1, 1, 1));
  cases.push_back({"5000 collinear points and one outlier", MakeCloud(line)});
  {
    PointCloud c = ShapeCloud(Shape::kSphere, 2000, 1);
    c.points[17].y() = nan;
    cases.push_back({"sphere with a NaN", c});
    c.points[17].y() = inf;
    cases.push_back({"sphere with an inf", c});
    c = ShapeCloud(Shape::kSphere, 2000, 1);
    c.origin.x() = nan;
    cases.push_back({"sphere with a NaN origin", c});
  }
  {
    PointCloud c = ShapeCloud(Shape::kBox, 2000, 1);
    for (std::size_t i = 0; i < c.size(); i += 3) c.points[i].setConstant(nan);
    cases.push_back({"box with every third point NaN", c});
  }
  return cases;
}

TEST(EsfTest, DegenerateCloudsFailQuicklyWithAReason) {
  for (const DegenerateCase& c : DegenerateClouds()) {
    const auto t0 = std::chrono::steady_clock::now();
    const EsfResult ours = ComputeEsf(c.cloud);
    const EsfResult pcl = ComputePclEsf(c.cloud);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::cout << "[ESF] " << c.name << ": " << ours.reason << " | PCL guard: " << pcl.reason << " ("
              << seconds << " s)\n";
    EXPECT_FALSE(ours.ok) << c.name;
    EXPECT_FALSE(ours.reason.empty()) << c.name;
    EXPECT_TRUE(ours.histogram.isZero()) << c.name;
    EXPECT_FALSE(pcl.ok) << c.name;
    EXPECT_FALSE(pcl.reason.empty()) << c.name;
    EXPECT_LT(seconds, 5.0) << c.name << " took too long (hang guard, not a benchmark)";
  }
}

TEST(EsfTest, InvalidOptionsThrow) {
  const PointCloud cloud = ShapeCloud(Shape::kSphere, 100, 1);
  EsfOptions options;
  options.samples = 0;
  EXPECT_THROW(ComputeEsf(cloud, options), Error);
  options = EsfOptions{};
  options.grid_size = 63;
  EXPECT_THROW(ComputeEsf(cloud, options), Error);
  options.grid_size = 8;
  EXPECT_THROW(options.Check(), Error);
  options.grid_size = 32;
  EXPECT_NO_THROW(options.Check());
  options.threads = -1;
  EXPECT_THROW(options.Check(), Error);
}

// Timing printout for the report, not an assertion (DESIGN.md: benchmarks, never timed tests).
TEST(EsfTest, TimeAgainstPclOn5kPoints) {
  const PointCloud cloud = ShapeCloud(Shape::kBox, 5000, 31);
  const auto median_seconds = [](auto&& run) {
    std::vector<double> times;
    for (int i = 0; i < 7; ++i) {
      const auto t0 = std::chrono::steady_clock::now();
      run();
      times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::sort(times.begin(), times.end());
    return times[times.size() / 2];
  };
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const double ours_1 = median_seconds([&] { EXPECT_TRUE(ComputeEsf(cloud).ok); });
  omp_set_num_threads(threads);
  const double ours = median_seconds([&] { EXPECT_TRUE(ComputeEsf(cloud).ok); });
  const double pcl = median_seconds([&] { EXPECT_TRUE(ComputePclEsf(cloud).ok); });
  std::cout << "[ESF] 5000-point box, median of 7: ours " << ours_1 * 1e3 << " ms (1 thread), "
            << ours * 1e3 << " ms (" << threads << " threads); PCL " << pcl * 1e3
            << " ms; PCL/ours(1 thread) = " << pcl / ours_1 << "\n";
}

TEST(ChiSquareDistanceTest, Definition) {
  const std::vector<float> a = {0.5f, 0.5f, 0.0f, 0.0f};
  const std::vector<float> b = {0.0f, 0.0f, 0.5f, 0.5f};
  const std::vector<float> c = {0.25f, 0.25f, 0.5f, 0.0f};
  EXPECT_DOUBLE_EQ(ChiSquareDistance(a.data(), a.data(), 4), 0.0);
  EXPECT_DOUBLE_EQ(ChiSquareDistance(a.data(), b.data(), 4), 2.0);  // disjoint: the maximum
  // (0.25^2/0.75) * 2 + 0.5^2/0.5, the empty last bin skipped.
  EXPECT_NEAR(ChiSquareDistance(a.data(), c.data(), 4), 2 * 0.0625 / 0.75 + 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(ChiSquareDistance(a.data(), c.data(), 4),
                   ChiSquareDistance(c.data(), a.data(), 4));
  EXPECT_DOUBLE_EQ(ChiSquareDistance(a.data(), c.data(), 0), 0.0);
}

}  // namespace
}  // namespace uwscan::perception
