#include "perception/preprocessing/sphere_fit.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

std::vector<Eigen::Vector3d> CapPoints(const Eigen::Vector3d& centre, double radius, int count,
                                       double noise_m, std::uint64_t seed) {
  // A cap of the sphere facing -z, as a scanner sees it (about a quarter of the sphere).
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> angle(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, noise_m);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d dir = Eigen::Vector3d{angle(rng), angle(rng), -1.5}.normalized();
    points.push_back(centre + (radius + (noise_m > 0 ? noise(rng) : 0.0)) * dir);
  }
  return points;
}

TEST(SphereFit, RecoversAnExactSphereFromACap) {
  const Eigen::Vector3d centre(0.1, -0.2, 1.25);
  const SphereFit fit = FitSphere(CapPoints(centre, 0.1, 500, 0.0, 1));
  EXPECT_NEAR((fit.centre - centre).norm(), 0.0, 1e-12);
  EXPECT_NEAR(fit.radius_m, 0.1, 1e-12);
  EXPECT_LT(fit.rms_m, 1e-12);
}

TEST(SphereFit, NoisyCapGivesRadiusWithinNoiseAndRmsNearTheNoise) {
  const SphereFit fit = FitSphere(CapPoints(Eigen::Vector3d(0, 0, 1), 0.1, 20000, 0.001, 2));
  EXPECT_NEAR(fit.radius_m, 0.1, 5e-4);
  EXPECT_NEAR(fit.rms_m, 0.001, 1e-4);
}

TEST(SphereFit, FarFromTheOriginAsAccurateAsNearIt) {
  const Eigen::Vector3d centre(4.0e5, -3.0e5, 120.0);
  const SphereFit fit = FitSphere(CapPoints(centre, 0.1, 500, 0.0, 3));
  EXPECT_NEAR(fit.radius_m, 0.1, 1e-7);
  EXPECT_NEAR((fit.centre - centre).norm(), 0.0, 1e-6);
}

TEST(SphereFit, RejectsDegenerateInput) {
  EXPECT_THROW(FitSphere(std::vector<Eigen::Vector3d>(3, Eigen::Vector3d::Zero())), Error);
  std::vector<Eigen::Vector3d> plane;
  for (int i = 0; i < 50; ++i) plane.emplace_back(i % 7 * 0.01, i / 7 * 0.01, 1.0);
  EXPECT_THROW(FitSphere(plane), Error);
  std::vector<Eigen::Vector3d> with_nan = CapPoints(Eigen::Vector3d(0, 0, 1), 0.1, 10, 0.0, 4);
  with_nan[3].x() = std::nan("");
  EXPECT_THROW(FitSphere(with_nan), Error);
}

}  // namespace
}  // namespace uwscan::perception
