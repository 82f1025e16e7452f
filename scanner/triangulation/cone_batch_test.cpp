// The batched cone intersection must give what the per-ray function gives, lane by lane,
// including every miss status and the degenerate cones.
#include "scanner/triangulation/cone_batch.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

namespace uwscan::scanner {
namespace {

EllipticCone RandomCone(std::mt19937_64& rng, double b) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  EllipticCone cone;
  cone.T_C_Q.linear() =
      Eigen::AngleAxisd(3.0 * unit(rng),
                        Eigen::Vector3d{unit(rng), unit(rng), unit(rng)}.normalized())
          .toRotationMatrix();
  cone.T_C_Q.translation() = Eigen::Vector3d{unit(rng), unit(rng), unit(rng)};
  cone.a = 0.2 + std::abs(unit(rng));
  cone.b = b;
  cone.beta_min_rad = 0.3;
  cone.beta_max_rad = 2.6;
  return cone;
}

void ExpectBlockMatchesPerRay(const EllipticCone& cone, std::mt19937_64& rng, int blocks) {
  const PreparedCone prepared = PrepareCone(cone);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  int hits = 0;
  for (int k = 0; k < blocks; ++k) {
    RayBlock rays;
    Ray per_ray[RayBlock::kSize];
    for (size_t lane = 0; lane < RayBlock::kSize; ++lane) {
      Ray ray;
      ray.origin = 2.0 * Eigen::Vector3d{unit(rng), unit(rng), unit(rng)};
      // Aim half of the rays at points of the cone so that hits are common.
      if (lane % 2 == 0) {
        const double height = 0.2 + std::abs(gauss(rng));
        const Eigen::Vector3d target = cone.Point(height, 3.2 * std::abs(unit(rng)));
        ray.direction = (target - ray.origin).normalized();
      } else {
        ray.direction = Eigen::Vector3d{gauss(rng), gauss(rng), gauss(rng)}.normalized();
      }
      if (lane == 5) ray.origin = cone.T_C_Q.translation();  // from the apex
      if (lane == 7) ray.direction *= 3.0;                   // not unit length
      per_ray[lane] = ray;
      rays.ox[lane] = ray.origin.x(), rays.oy[lane] = ray.origin.y(),
      rays.oz[lane] = ray.origin.z();
      rays.dx[lane] = ray.direction.x(), rays.dy[lane] = ray.direction.y();
      rays.dz[lane] = ray.direction.z();
    }
    HitBlock block;
    IntersectRayConeBlock(prepared, rays, 0.0, &block);
    for (size_t lane = 0; lane < RayBlock::kSize; ++lane) {
      const RayHit expected = IntersectRayCone(per_ray[lane], prepared);
      if (lane == 5) {
        // From the apex itself the roots are rounding noise: both forms must call it a miss,
        // but which miss depends on the last bit of the transformed origin.
        EXPECT_FALSE(expected.ok());
        EXPECT_NE(block.Status(lane), HitStatus::kHit);
        continue;
      }
      ASSERT_EQ(block.Status(lane), expected.status) << "block " << k << " lane " << lane;
      if (expected.ok()) {
        ++hits;
        EXPECT_NEAR(block.t[lane], expected.t, 1e-12 * (1.0 + std::abs(expected.t)));
        EXPECT_LT(
            (Eigen::Vector3d(block.x[lane], block.y[lane], block.z[lane]) - expected.point).norm(),
            1e-12 * (1.0 + expected.point.norm()) * (1.0 + expected.t));
      }
    }
  }
  EXPECT_GT(hits, blocks);  // the comparison covered real hits, not only misses
}

TEST(ConeBatchTest, MatchesPerRayOnGeneralCones) {
  std::mt19937_64 rng(3);
  for (double b : {0.4, -0.25, 0.05}) ExpectBlockMatchesPerRay(RandomCone(rng, b), rng, 400);
}

TEST(ConeBatchTest, MatchesPerRayOnDegenerateCones) {
  std::mt19937_64 rng(4);
  EllipticCone circular = RandomCone(rng, 0.0);
  circular.b = circular.a;  // a = b
  ExpectBlockMatchesPerRay(circular, rng, 200);
  ExpectBlockMatchesPerRay(RandomCone(rng, 1e-9), rng, 200);  // nearly a plane
  ExpectBlockMatchesPerRay(RandomCone(rng, 0.0), rng, 200);   // exactly a plane
}

// The cone's implicit function in {C}, F(x) = y^2 - b^2 (z^2 - u^2) at s = S_C x + s_origin (for
// b = 0 the plane F = y): differentiated numerically here, so that the grazing test is checked
// against a normal the block does not compute the same way.
Eigen::Vector3d NumericalNormal(const PreparedCone& cone, const Eigen::Vector3d& x_C) {
  const auto f = [&](const Eigen::Vector3d& x) {
    const Eigen::Vector3d s = cone.S_C * x + cone.s_origin;
    if (cone.b == 0.0) return s.y();
    return s.y() * s.y() - cone.b * cone.b * (s.z() * s.z() - s.x() * s.x());
  };
  constexpr double kStep = 1e-6;
  Eigen::Vector3d gradient;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d step = kStep * Eigen::Vector3d::Unit(k);
    gradient[k] = (f(x_C + step) - f(x_C - step)) / (2.0 * kStep);
  }
  return gradient;
}

// Random rays against `cone` with the grazing test at min_angle_rad; counts the hits kept and
// rejected, and checks every lane against the per-ray function and the numerical normal. Lane 3
// of the first block has a zero direction (a pixel outside the table): a kParallel miss.
void ExpectGrazingHitsParallel(const PreparedCone& cone, std::mt19937_64& rng, int* kept,
                               int* rejected) {
  const double min_sin2 = std::pow(std::sin(0.35), 2);  // about 20 degrees
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int k = 0; k < 300; ++k) {
    RayBlock rays;
    Ray per_ray[RayBlock::kSize];
    for (size_t lane = 0; lane < RayBlock::kSize; ++lane) {
      Ray& ray = per_ray[lane];
      ray.origin = 2.0 * Eigen::Vector3d{unit(rng), unit(rng), unit(rng)};
      ray.direction = Eigen::Vector3d{unit(rng), unit(rng), unit(rng)};
      if (k == 0 && lane == 3) ray.direction.setZero();
      rays.ox[lane] = ray.origin.x(), rays.oy[lane] = ray.origin.y(),
      rays.oz[lane] = ray.origin.z();
      rays.dx[lane] = ray.direction.x(), rays.dy[lane] = ray.direction.y();
      rays.dz[lane] = ray.direction.z();
    }
    HitBlock block;
    IntersectRayConeBlock(cone, rays, min_sin2, &block);
    for (size_t lane = 0; lane < RayBlock::kSize; ++lane) {
      const Eigen::Vector3d point(block.x[lane], block.y[lane], block.z[lane]);
      if (block.Status(lane) != HitStatus::kHit) {
        EXPECT_EQ(point, Eigen::Vector3d::Zero());  // a miss carries no point
        EXPECT_EQ(block.t[lane], 0.0);
      }
      if (k == 0 && lane == 3) {
        EXPECT_EQ(block.Status(lane), HitStatus::kParallel);
        continue;
      }
      const RayHit expected = IntersectRayCone(per_ray[lane], cone);
      if (!expected.ok()) {
        EXPECT_EQ(block.Status(lane), expected.status);
        continue;
      }
      const Eigen::Vector3d n = NumericalNormal(cone, expected.point);
      const Eigen::Vector3d& d = per_ray[lane].direction;
      const double sin2 = std::pow(n.dot(d), 2) / (n.squaredNorm() * d.squaredNorm());
      if (std::abs(sin2 - min_sin2) < 1e-6) continue;  // on the boundary: either is right
      if (sin2 < min_sin2) {
        ++*rejected;
        EXPECT_EQ(block.Status(lane), HitStatus::kParallel) << "block " << k << " lane " << lane;
      } else {
        ++*kept;
        ASSERT_EQ(block.Status(lane), HitStatus::kHit) << "block " << k << " lane " << lane;
        EXPECT_LT((point - expected.point).norm(), 1e-12 * (1.0 + expected.point.norm()));
      }
    }
  }
}

TEST(ConeBatchTest, HitsWithinTheMinimumAngleOfTheConeAreParallel) {
  std::mt19937_64 rng(5);
  for (double b : {0.4, 0.0}) {  // an elliptic cone, and the plane b = 0 degenerates to
    int kept = 0, rejected = 0;
    ExpectGrazingHitsParallel(PrepareCone(RandomCone(rng, b)), rng, &kept, &rejected);
    EXPECT_GT(kept, 50) << "b = " << b;
    EXPECT_GT(rejected, 50) << "b = " << b;
  }
}

}  // namespace
}  // namespace uwscan::scanner
