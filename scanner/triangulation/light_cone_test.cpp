#include "scanner/triangulation/light_cone.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/triangulation/light_plane.hpp"

namespace uwscan::scanner {
namespace {

constexpr double kPi = std::numbers::pi;

Eigen::Isometry3d RandomPose(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> shift(-0.3, 0.3);
  const Eigen::Quaterniond q =
      Eigen::Quaterniond{normal(rng), normal(rng), normal(rng), normal(rng)}.normalized();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.toRotationMatrix();
  T.translation() = Eigen::Vector3d{shift(rng), shift(rng), shift(rng)};
  return T;
}

EllipticCone MakeCone(double a, double b, const Eigen::Isometry3d& T_C_Q, double beta_min_rad = 0.0,
                      double beta_max_rad = kPi, double h_min_m = 0.0) {
  EllipticCone cone;
  cone.T_C_Q = T_C_Q;
  cone.a = a;
  cone.b = b;
  cone.beta_min_rad = beta_min_rad;
  cone.beta_max_rad = beta_max_rad;
  cone.h_min_m = h_min_m;
  return cone;
}

// A ray given in the cone frame {Q}, expressed in {C}.
Ray RayFromQ(const EllipticCone& cone, const Eigen::Vector3d& origin_Q,
             const Eigen::Vector3d& direction_Q) {
  return Ray{cone.T_C_Q * origin_Q, cone.T_C_Q.linear() * direction_Q};
}

RayHit Intersect(const EllipticCone& cone, const Eigen::Vector3d& origin_Q,
                 const Eigen::Vector3d& direction_Q) {
  return IntersectRayCone(RayFromQ(cone, origin_Q, direction_Q), cone);
}

Eigen::Vector3d PointQ(double a, double b, double h, double beta) {
  return Eigen::Vector3d(a * h * std::cos(beta), b * h * std::sin(beta), h);
}

bool IsMissWithoutNaN(const RayHit& hit) {
  return !hit.ok() && std::isfinite(hit.t) && hit.point.allFinite();
}

// ---------------------------------------------------------------------------------------------
// Points on the lit sheet, seen from outside the (convex) solid nappe along a direction with
// a positive component on the outward normal: the point is where the ray enters the solid, so
// it is the first lit intersection and must be returned exactly.

TEST(IntersectRayCone, HitsPointsOnConeFromOutside) {
  std::mt19937_64 rng(101);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int c = 0; c < 30; ++c) {
    const double a = 0.2 + 1.3 * unit(rng);
    // Every fourth cone circular (a = b); |b| log-uniform in [0.01, 1] with a random sign.
    const double b_abs = (c % 4 == 0) ? a : std::pow(10.0, -2.0 * unit(rng));
    const double b = (c % 2 == 0) ? b_abs : -b_abs;
    const EllipticCone cone = MakeCone(a, b, RandomPose(rng), 0.2, 2.9);
    for (int i = 0; i < 200; ++i) {
      const double h = 0.3 + 1.7 * unit(rng);
      const double beta = 0.2 + 2.7 * unit(rng);
      const Eigen::Vector3d p_Q = PointQ(a, b, h, beta);
      // Gradient of (x/a)^2 + (y/b)^2 - z^2: outward from the solid nappe.
      const Eigen::Vector3d n_Q =
          Eigen::Vector3d(p_Q.x() / (a * a), p_Q.y() / (b * b), -p_Q.z()).normalized();
      Eigen::Vector3d tangent{normal(rng), normal(rng), normal(rng)};
      tangent = (tangent - tangent.dot(n_Q) * n_Q).normalized();
      const Eigen::Vector3d w = (n_Q + 0.7 * tangent).normalized();
      const double distance_m = 0.2 + 2.8 * unit(rng);
      const double speed = 0.5 + 2.5 * unit(rng);  // |direction| != 1: t is in its units
      const RayHit hit = Intersect(cone, p_Q + distance_m * w, -speed * w);
      ASSERT_TRUE(hit.ok()) << "cone " << c << " point " << i << ": " << ToString(hit.status);
      EXPECT_LT((hit.point - cone.T_C_Q * p_Q).norm(), 1e-9);
      EXPECT_NEAR(hit.t * speed, distance_m, 1e-9);
    }
  }
}

TEST(IntersectRayCone, CircularConeMatchesClosedForm) {
  // a = b = 1: the circle x^2 + y^2 = 1 at z = 1; a ray along +x at y = 0.3 enters at
  // x = -sqrt(0.91), on the sheet y > 0 (lit for b > 0) at beta = atan2(0.3, -sqrt(0.91)).
  std::mt19937_64 rng(102);
  for (int trial = 0; trial < 10; ++trial) {
    const EllipticCone cone = MakeCone(1.0, 1.0, RandomPose(rng));
    const RayHit hit = Intersect(cone, Eigen::Vector3d(-2.0, 0.3, 1.0), Eigen::Vector3d::UnitX());
    ASSERT_TRUE(hit.ok());
    EXPECT_NEAR(hit.t, 2.0 - std::sqrt(0.91), 1e-14);
    EXPECT_LT((hit.point - cone.T_C_Q * Eigen::Vector3d(-std::sqrt(0.91), 0.3, 1.0)).norm(), 1e-14);
  }
}

// ---------------------------------------------------------------------------------------------
// Nearly planar cones: the fan hardly bends. The result must tend to the plane y_Q = 0.

class NearlyFlatCone : public ::testing::TestWithParam<double> {};

TEST_P(NearlyFlatCone, MatchesPlaneIntersection) {
  const double b = GetParam();
  const double a = 0.7;
  std::mt19937_64 rng(103);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const EllipticCone cone = MakeCone(a, b, RandomPose(rng));
  const PreparedCone prepared = PrepareCone(cone);
  const Eigen::Vector3d normal_C = cone.T_C_Q.linear().col(1);
  const Plane plane_C{normal_C, normal_C.dot(cone.T_C_Q.translation())};
  for (int i = 0; i < 500; ++i) {
    // Crossing of the plane y_Q = 0 inside the wedge, at h <= 0.9 m, by a ray within ~17 deg
    // of the plane normal, from either side.
    const double z = 0.3 + 0.6 * unit(rng);
    const double u = (2.0 * unit(rng) - 1.0) * 0.9;
    const Eigen::Vector3d target_Q(a * u * z, 0.0, z);
    const double side = (i % 2 == 0) ? 1.0 : -1.0;
    const Eigen::Vector3d d_Q =
        Eigen::Vector3d{0.3 * (2.0 * unit(rng) - 1.0), side, 0.3 * (2.0 * unit(rng) - 1.0)}
            .normalized();
    const double distance_m = 0.5 + 1.5 * unit(rng);
    const Ray ray_C = RayFromQ(cone, target_Q - distance_m * d_Q, d_Q);

    const RayHit plane_hit = IntersectRayPlane(ray_C, plane_C);
    const RayHit hit = IntersectRayCone(ray_C, prepared);
    ASSERT_TRUE(plane_hit.ok());
    ASSERT_TRUE(hit.ok()) << "ray " << i << ": " << ToString(hit.status);
    if (std::abs(b) <= 1e-9) {
      EXPECT_LT((hit.point - plane_hit.point).norm(), 1e-9);
    }
    // The lit sheet y = b s(t), s = sqrt(z^2 - (x/a)^2) along the ray, is crossed delta
    // further than the plane: d_y delta = b s(t0 + delta), so to O(b^3) delta =
    // b s0 / (d_y - b s'), s' = (z d_z - (x/a)(d_x/a)) / s0. The two roots are only ~2e-9
    // apart for |b| = 1e-9: resolving that to 1e-14 needs the cancellation-free discriminant.
    const double s0 = z * std::sqrt(1.0 - u * u);
    const double ds = (z * d_Q.z() - u * z * d_Q.x() / a) / s0;
    EXPECT_NEAR(hit.t - plane_hit.t, b * s0 / (d_Q.y() - b * ds), 1e-14);
  }
}

std::string FlatnessName(const ::testing::TestParamInfo<double>& info) {
  static constexpr std::array<const char*, 5> kNames = {"b0", "b1e_9", "bminus1e_9", "b1e_6",
                                                        "bminus1e_6"};
  return kNames[info.index];
}

INSTANTIATE_TEST_SUITE_P(IntersectRayCone, NearlyFlatCone,
                         ::testing::Values(0.0, 1e-9, -1e-9, 1e-6, -1e-6), FlatnessName);

TEST(IntersectRayCone, FlatConeOutsideWedgeOrParallel) {
  std::mt19937_64 rng(104);
  const EllipticCone cone = MakeCone(0.5, 0.0, RandomPose(rng));
  // Crosses y_Q = 0 at x = 0.6, z = 1: outside |x| <= a z = 0.5.
  const RayHit outside = Intersect(cone, Eigen::Vector3d(0.6, -1.0, 1.0), Eigen::Vector3d::UnitY());
  EXPECT_EQ(outside.status, HitStatus::kOutsideSurface);
  EXPECT_TRUE(IsMissWithoutNaN(outside));
  const RayHit inside = Intersect(cone, Eigen::Vector3d(0.4, -1.0, 1.0), Eigen::Vector3d::UnitY());
  ASSERT_TRUE(inside.ok());
  EXPECT_NEAR(inside.t, 1.0, 1e-15);
  const RayHit parallel =
      Intersect(cone, Eigen::Vector3d(0.0, 0.1, 1.0), Eigen::Vector3d(0.6, 0.0, 0.8));
  EXPECT_EQ(parallel.status, HitStatus::kParallel);
}

// ---------------------------------------------------------------------------------------------
// Sheets: the cone y^2 = b^2 (z^2 - u^2) has two sheets; only y_Q with the sign of b is lit.

TEST(IntersectRayCone, PicksLitSheetWhenRayCrossesBoth) {
  std::mt19937_64 rng(105);
  const double a = 0.6;
  const double x = 0.1;
  const double sheet_y = 0.3 * std::sqrt(1.0 - (x / a) * (x / a));  // |y| of both sheets at z=1
  for (const double b : {0.3, -0.3}) {
    const EllipticCone cone = MakeCone(a, b, RandomPose(rng));
    const double lit_y = b > 0.0 ? sheet_y : -sheet_y;
    // From y = -2 upwards and from y = +2 downwards: one of the two meets the wrong sheet
    // first and must skip it.
    const RayHit up = Intersect(cone, Eigen::Vector3d(x, -2.0, 1.0), Eigen::Vector3d::UnitY());
    const RayHit down = Intersect(cone, Eigen::Vector3d(x, 2.0, 1.0), -Eigen::Vector3d::UnitY());
    ASSERT_TRUE(up.ok());
    ASSERT_TRUE(down.ok());
    EXPECT_NEAR(up.t, 2.0 + lit_y, 1e-14) << "b = " << b;
    EXPECT_NEAR(down.t, 2.0 - lit_y, 1e-14) << "b = " << b;
    EXPECT_LT((up.point - down.point).norm(), 1e-14);
    EXPECT_LT((up.point - cone.T_C_Q * Eigen::Vector3d(x, lit_y, 1.0)).norm(), 1e-14);
    // From between the sheets towards the unlit one: the lit root is behind.
    const RayHit wrong = Intersect(cone, Eigen::Vector3d(x, 0.0, 1.0),
                                   Eigen::Vector3d(0.0, b > 0.0 ? -1.0 : 1.0, 0.0));
    EXPECT_EQ(wrong.status, HitStatus::kOutsideSurface);
    EXPECT_TRUE(IsMissWithoutNaN(wrong));
  }
}

// ---------------------------------------------------------------------------------------------
// The apex and generators: where the quadric degenerates.

TEST(IntersectRayCone, RayThroughApexIsAMissNotNaN) {
  std::mt19937_64 rng(106);
  std::normal_distribution<double> normal(0.0, 1.0);
  const EllipticCone cone = MakeCone(0.6, 0.2, RandomPose(rng));
  for (int i = 0; i < 1000; ++i) {
    // Includes directions inside the cone (through the apex into the lit nappe).
    const Eigen::Vector3d v = Eigen::Vector3d{normal(rng), normal(rng), normal(rng)}.normalized();
    const RayHit through = Intersect(cone, -0.8 * v, v);
    EXPECT_TRUE(through.status == HitStatus::kOutsideSurface ||
                through.status == HitStatus::kNoIntersection)
        << ToString(through.status);
    EXPECT_TRUE(IsMissWithoutNaN(through));
    const RayHit from_apex = Intersect(cone, Eigen::Vector3d::Zero(), v);
    EXPECT_TRUE(IsMissWithoutNaN(from_apex)) << ToString(from_apex.status);
  }
  // Straight up the axis from below.
  const RayHit axis = Intersect(cone, Eigen::Vector3d(0.0, 0.0, -1.0), Eigen::Vector3d::UnitZ());
  EXPECT_TRUE(IsMissWithoutNaN(axis));
}

TEST(IntersectRayCone, LineOnTheConeIsParallel) {
  std::mt19937_64 rng(107);
  const double a = 0.6;
  const double b = 0.5;
  const EllipticCone cone = MakeCone(a, b, RandomPose(rng));
  for (const double beta : {0.3, 1.2, 2.5}) {
    const Eigen::Vector3d generator = PointQ(a, b, 1.0, beta).normalized();
    const RayHit along = Intersect(cone, -0.5 * generator, generator);
    EXPECT_EQ(along.status, HitStatus::kParallel) << "beta = " << beta;
  }
  // Parallel to the generator beta = pi/2, (0, b, 1), inside its tangent plane y = b z: the
  // line touches the cone only at infinity.
  const RayHit tangent_plane =
      Intersect(cone, Eigen::Vector3d(0.3, 0.0, 0.0), Eigen::Vector3d(0.0, b, 1.0));
  EXPECT_EQ(tangent_plane.status, HitStatus::kParallel);
}

TEST(IntersectRayCone, RayParallelToGeneratorHasOneRoot) {
  // a = 0.6, b = 0.5, direction (0, b, 1) parallel to the generator beta = pi/2. Along
  // o + t d the quadric is linear: F(t) = F(o) + 2 t o^T M d with M = diag(1/a^2, 1/b^2, -1).
  // o = (0.3, -0.2, 0): F = 0.41, o^T M d = -0.4, so t = 0.5125 at (0.3, 0.05625, 0.5125).
  std::mt19937_64 rng(108);
  for (int trial = 0; trial < 50; ++trial) {
    const EllipticCone cone = MakeCone(0.6, 0.5, RandomPose(rng));
    const Eigen::Vector3d d_Q(0.0, 0.5, 1.0);
    const RayHit hit = Intersect(cone, Eigen::Vector3d(0.3, -0.2, 0.0), d_Q);
    ASSERT_TRUE(hit.ok()) << ToString(hit.status);
    EXPECT_NEAR(hit.t, 0.5125, 1e-14);
    EXPECT_LT((hit.point - cone.T_C_Q * Eigen::Vector3d(0.3, 0.05625, 0.5125)).norm(), 1e-14);
    // Mirrored origin: the only finite root (t = -0.5125) is behind. The second root is at
    // infinity, where the ray runs along the lit sheet; rounding must not turn it into a
    // hit 1e16 m away.
    const RayHit behind = Intersect(cone, Eigen::Vector3d(0.3, 0.2, 0.0), d_Q);
    EXPECT_EQ(behind.status, HitStatus::kBehind);
  }
}

// ---------------------------------------------------------------------------------------------
// Misses and the lit range.

TEST(IntersectRayCone, MissesAndRootsBehind) {
  std::mt19937_64 rng(109);
  const EllipticCone cone = MakeCone(0.6, 0.3, RandomPose(rng));
  // x = 3 at z = 1 is far outside the ellipse (semi-axis 0.6): no real root.
  const RayHit miss = Intersect(cone, Eigen::Vector3d(3.0, -1.0, 1.0), Eigen::Vector3d::UnitY());
  EXPECT_EQ(miss.status, HitStatus::kNoIntersection);
  EXPECT_TRUE(IsMissWithoutNaN(miss));
  // Beyond both sheets, heading away.
  const RayHit away = Intersect(cone, Eigen::Vector3d(0.1, 2.0, 1.0), Eigen::Vector3d::UnitY());
  EXPECT_EQ(away.status, HitStatus::kBehind);
  EXPECT_TRUE(IsMissWithoutNaN(away));
}

TEST(IntersectRayCone, BetaOutsideLitRange) {
  // The ray along -y at x = a cos(0.5), z = 1 meets the lit sheet at beta = 0.5, then the
  // unlit sheet.
  std::mt19937_64 rng(110);
  const Eigen::Isometry3d T = RandomPose(rng);
  const Eigen::Vector3d origin_Q(0.6 * std::cos(0.5), 2.0, 1.0);
  const EllipticCone narrow = MakeCone(0.6, 0.3, T, 1.0, 2.0);
  EXPECT_EQ(Intersect(narrow, origin_Q, -Eigen::Vector3d::UnitY()).status,
            HitStatus::kOutsideSurface);
  const EllipticCone wide = MakeCone(0.6, 0.3, T, 0.49, 2.0);
  const RayHit hit = Intersect(wide, origin_Q, -Eigen::Vector3d::UnitY());
  ASSERT_TRUE(hit.ok());
  EXPECT_NEAR(hit.t, 2.0 - 0.3 * std::sin(0.5), 1e-14);
  // And the other end of the range, beta = 2.5 > beta_max.
  const Eigen::Vector3d origin2_Q(0.6 * std::cos(2.5), 2.0, 1.0);
  EXPECT_EQ(Intersect(narrow, origin2_Q, -Eigen::Vector3d::UnitY()).status,
            HitStatus::kOutsideSurface);
  EXPECT_TRUE(
      Intersect(MakeCone(0.6, 0.3, T, 1.0, 2.51), origin2_Q, -Eigen::Vector3d::UnitY()).ok());
}

TEST(IntersectRayCone, BelowMinimumHeight) {
  std::mt19937_64 rng(111);
  const Eigen::Isometry3d T = RandomPose(rng);
  const Eigen::Vector3d origin_Q(0.1, 2.0, 0.3);
  const RayHit low =
      Intersect(MakeCone(0.6, 0.3, T, 0.0, kPi, 0.5), origin_Q, -Eigen::Vector3d::UnitY());
  EXPECT_EQ(low.status, HitStatus::kOutsideSurface);
  const RayHit high =
      Intersect(MakeCone(0.6, 0.3, T, 0.0, kPi, 0.2), origin_Q, -Eigen::Vector3d::UnitY());
  ASSERT_TRUE(high.ok());
  EXPECT_NEAR(high.t, 2.0 - 0.3 * std::sqrt(0.09 - (0.1 / 0.6) * (0.1 / 0.6)), 1e-14);
}

TEST(IntersectRayCone, NaNInputIsNeverAHit) {
  const EllipticCone cone = MakeCone(0.6, 0.3, Eigen::Isometry3d::Identity());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int k = 0; k < 6; ++k) {
    Ray ray{Eigen::Vector3d(0.1, -2.0, 1.0), Eigen::Vector3d::UnitY()};
    (k < 3 ? ray.origin : ray.direction)(k % 3) = nan;
    const RayHit hit = IntersectRayCone(ray, cone);
    EXPECT_TRUE(IsMissWithoutNaN(hit)) << "component " << k;
  }
}

// ---------------------------------------------------------------------------------------------
// Random rays against an independent reference: the textbook quadratic in long double (64-bit
// mantissa) with the lit test by atan2. Rays whose reference answer sits within 1e-6 of a
// decision boundary are skipped; everything else must agree in status and t.

struct Reference {
  bool usable = false;
  HitStatus status = HitStatus::kNoIntersection;
  double t = 0.0;
  double t_tol = 0.0;  // rounding in the coefficients moves a root by ~ eps t (size of A) / A
};

Reference ReferenceIntersect(const EllipticCone& cone, const Eigen::Vector3d& o_Q,
                             const Eigen::Vector3d& d_Q) {
  using L = long double;
  const L a2 = L(cone.a) * cone.a;
  const L b2 = L(cone.b) * cone.b;
  const L ox = o_Q.x(), oy = o_Q.y(), oz = o_Q.z();
  const L dx = d_Q.x(), dy = d_Q.y(), dz = d_Q.z();
  const L qa = b2 * dx * dx + a2 * dy * dy - a2 * b2 * dz * dz;
  const L qb = b2 * ox * dx + a2 * oy * dy - a2 * b2 * oz * dz;
  const L qc = b2 * ox * ox + a2 * oy * oy - a2 * b2 * oz * oz;
  const L disc = qb * qb - qa * qc;
  Reference ref;
  if (std::fabs(qa) < 1e-6L || std::fabs(disc) < 1e-6L * (qb * qb + std::fabs(qa * qc))) {
    return ref;  // near-degenerate: the double-precision answer may legitimately differ
  }
  ref.usable = true;
  if (disc < 0) {
    return ref;
  }
  std::array<L, 2> roots = {(-qb - std::sqrt(disc)) / qa, (-qb + std::sqrt(disc)) / qa};
  std::sort(roots.begin(), roots.end());
  bool ahead = false;
  for (const L t : roots) {
    if (t < 0) {
      if (t > -1e-6L) {
        ref.usable = false;
      }
      continue;
    }
    ahead = true;
    const L x = ox + t * dx, y = oy + t * dy, z = oz + t * dz;
    const L beta = std::atan2(y / L(cone.b), x / L(cone.a));
    const L margin =
        std::min({std::fabs(beta - L(cone.beta_min_rad)), std::fabs(beta - L(cone.beta_max_rad)),
                  std::fabs(z - L(cone.h_min_m))});
    if (margin < 1e-6L) {
      ref.usable = false;
    }
    if (beta >= cone.beta_min_rad && beta <= cone.beta_max_rad && z > cone.h_min_m) {
      ref.status = HitStatus::kHit;
      ref.t = static_cast<double>(t);
      const L size_a = b2 * dx * dx + a2 * dy * dy + a2 * b2 * dz * dz;
      ref.t_tol = static_cast<double>(1e-13L * (1 + t) * size_a / std::fabs(qa));
      return ref;
    }
  }
  ref.status = ahead ? HitStatus::kOutsideSurface : HitStatus::kBehind;
  return ref;
}

TEST(IntersectRayCone, RandomRaysAgreeWithLongDoubleReference) {
  std::mt19937_64 rng(112);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::array<int, 6> seen{};
  int compared = 0;
  for (int c = 0; c < 8; ++c) {
    const double b = (c % 2 == 0 ? 1.0 : -1.0) * (0.05 + 0.5 * unit(rng));
    const double a = 0.3 + unit(rng);
    const EllipticCone cone = MakeCone(a, b, RandomPose(rng), 0.4, 2.6, 0.1);
    const PreparedCone prepared = PrepareCone(cone);
    for (int i = 0; i < 5000; ++i) {
      const Eigen::Vector3d o_Q{2.0 * unit(rng) - 1.0, 2.0 * unit(rng) - 1.0,
                                2.5 * unit(rng) - 0.5};
      const Eigen::Vector3d d_Q =
          Eigen::Vector3d{normal(rng), normal(rng), normal(rng)}.normalized();
      const Reference ref = ReferenceIntersect(cone, o_Q, d_Q);
      if (!ref.usable) {
        continue;
      }
      const RayHit hit = IntersectRayCone(RayFromQ(cone, o_Q, d_Q), prepared);
      ++compared;
      ++seen[static_cast<int>(ref.status)];
      ASSERT_EQ(hit.status, ref.status)
          << "cone " << c << " ray " << i << ": got " << ToString(hit.status) << ", reference "
          << ToString(ref.status);
      if (hit.ok()) {
        EXPECT_NEAR(hit.t, ref.t, ref.t_tol);
      }
    }
  }
  EXPECT_GT(compared, 35000);
  // Every outcome the reference distinguishes occurs many times.
  for (const HitStatus s : {HitStatus::kHit, HitStatus::kNoIntersection, HitStatus::kBehind,
                            HitStatus::kOutsideSurface}) {
    EXPECT_GT(seen[static_cast<int>(s)], 1000) << ToString(s);
  }
}

// ---------------------------------------------------------------------------------------------
// Contract of the cone itself.

TEST(EllipticCone, PointIsParametricFormInCameraFrame) {
  std::mt19937_64 rng(113);
  const EllipticCone cone = MakeCone(0.6, -0.2, RandomPose(rng));
  const Eigen::Vector3d p_Q = cone.T_C_Q.inverse() * cone.Point(1.3, 0.7);
  EXPECT_NEAR(p_Q.x(), 0.6 * 1.3 * std::cos(0.7), 1e-14);
  EXPECT_NEAR(p_Q.y(), -0.2 * 1.3 * std::sin(0.7), 1e-14);
  EXPECT_NEAR(p_Q.z(), 1.3, 1e-14);
}

TEST(EllipticCone, CheckNamesTheBadField) {
  const auto expect_field = [](const EllipticCone& cone, const std::string& field) {
    try {
      cone.Check();
      ADD_FAILURE() << "expected uwscan::Error for " << field;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
    EXPECT_THROW(PrepareCone(cone), Error);
  };
  const EllipticCone good = MakeCone(0.6, 0.0, Eigen::Isometry3d::Identity());
  EXPECT_NO_THROW(good.Check());
  EllipticCone c = good;
  c.a = 0.0;
  expect_field(c, "EllipticCone.a");
  c = good;
  c.a = std::numeric_limits<double>::quiet_NaN();
  expect_field(c, "EllipticCone.a");
  c = good;
  c.b = std::numeric_limits<double>::infinity();
  expect_field(c, "EllipticCone.b");
  c = good;
  c.beta_min_rad = -0.1;
  expect_field(c, "beta_min_rad");
  c = good;
  c.beta_max_rad = 3.2;
  expect_field(c, "beta_max_rad");
  c = good;
  c.beta_min_rad = 2.0;
  c.beta_max_rad = 1.0;
  expect_field(c, "beta_max_rad");
  c = good;
  c.h_min_m = -0.01;
  expect_field(c, "h_min_m");
  c = good;
  c.T_C_Q.linear() *= 1.01;
  expect_field(c, "T_C_Q");
  c = good;
  c.T_C_Q.linear() = -Eigen::Matrix3d::Identity();  // a reflection, not a rotation
  expect_field(c, "T_C_Q");
}

}  // namespace
}  // namespace uwscan::scanner
