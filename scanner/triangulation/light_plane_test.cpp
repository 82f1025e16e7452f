#include "scanner/triangulation/light_plane.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/common/random_draws.hpp"

namespace uwscan::scanner {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Eigen::Vector3d RandomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  return DrawVector3(normal, rng).normalized();
}

// Two unit vectors spanning the plane orthogonal to `normal`.
std::pair<Eigen::Vector3d, Eigen::Vector3d> InPlaneBasis(const Eigen::Vector3d& normal) {
  const Eigen::Vector3d e1 = normal.unitOrthogonal();
  return {e1, normal.cross(e1)};
}

// n points uniform over a side_m square of the plane around `centre`, displaced along every
// axis by Gaussian noise of sigma_m.
std::vector<Eigen::Vector3d> PlanePoints(const Plane& plane, const Eigen::Vector3d& centre,
                                         double side_m, double sigma_m, int n,
                                         std::mt19937_64& rng) {
  const auto [e1, e2] = InPlaneBasis(plane.normal);
  const Eigen::Vector3d foot = centre - (plane.normal.dot(centre) - plane.offset_m) * plane.normal;
  std::uniform_real_distribution<double> along(-0.5 * side_m, 0.5 * side_m);
  std::normal_distribution<double> noise(0.0, sigma_m);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d jitter = DrawVector3(noise, rng);
    const Eigen::Vector2d in_plane = DrawVector2(along, rng);
    points.push_back(foot + in_plane.x() * e1 + in_plane.y() * e2 + jitter);
  }
  return points;
}

// The same plane may come back with the opposite normal; FitPlane makes offset >= 0.
double NormalAngle(const Eigen::Vector3d& n1, const Eigen::Vector3d& n2) {
  return std::acos(std::min(1.0, std::abs(n1.dot(n2))));
}

TEST(FitPlane, RecoversExactPlaneToRounding) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const Plane truth{RandomUnit(rng), 1.3};
    const auto points = PlanePoints(truth, Eigen::Vector3d(0.2, -0.1, 1.0), 1.0, 0.0, 50, rng);
    const PlaneFit fit = FitPlane(points);
    EXPECT_NEAR(fit.plane.normal.norm(), 1.0, 1e-15);
    EXPECT_LT((fit.plane.normal - truth.normal).norm(), 1e-13);
    EXPECT_NEAR(fit.plane.offset_m, truth.offset_m, 1e-13);
    EXPECT_LT(fit.rms_m, 1e-14);
    EXPECT_LT(fit.max_abs_m, 1e-14);
  }
}

TEST(FitPlane, NoisyPointsGiveRmsCloseToSigma) {
  std::mt19937_64 rng(12);
  const double sigma_m = 1e-3;
  const Plane truth{Eigen::Vector3d(0.1, -0.8, 0.3).normalized(), 0.9};
  const auto points = PlanePoints(truth, Eigen::Vector3d(0.0, 0.0, 1.2), 1.0, sigma_m, 4000, rng);
  const PlaneFit fit = FitPlane(points);
  // Only the normal component of isotropic noise is a residual: rms ~ sigma (1 +- 1/sqrt(2n)).
  EXPECT_NEAR(fit.rms_m, sigma_m, 0.05 * sigma_m);
  EXPECT_GT(fit.max_abs_m, 2.0 * sigma_m);
  EXPECT_LT(fit.max_abs_m, 6.0 * sigma_m);
  // Normal error ~ sigma / (side sqrt(n / 12)) ~ 5.5e-5 rad per axis. The fitted plane passes
  // through the points' centroid, which lies ~ sigma / sqrt(n) = 1.6e-5 m off the true plane
  // (checked at the patch centre, within 4 sigma). The offset adds the normal's error times the
  // 1.1 m from the origin to the patch centre along the plane: std ~ 6.4e-5 m (within 4 sigma).
  EXPECT_LT(NormalAngle(fit.plane.normal, truth.normal), 3e-4);
  const Eigen::Vector3d patch_centre =
      Eigen::Vector3d(0.0, 0.0, 1.2) - (truth.normal.z() * 1.2 - truth.offset_m) * truth.normal;
  EXPECT_LT(std::abs(fit.plane.normal.dot(patch_centre) - fit.plane.offset_m), 6.4e-5);
  EXPECT_NEAR(fit.plane.offset_m, truth.offset_m, 2.6e-4);
}

TEST(FitPlane, HugeCoordinatesKeepPrecisionByCentring) {
  // 1 m patch 100 km from the origin: raw (uncentred) second moments would be ~1e10 m^2 and
  // bury the 1 m^2 spread; centring keeps the normal to ~1e-11.
  std::mt19937_64 rng(13);
  const Eigen::Vector3d centre(1e5, -2e5, 5e4);
  const Eigen::Vector3d normal = Eigen::Vector3d(0.3, 0.2, -0.9).normalized();
  const Plane truth{normal, normal.dot(centre)};
  const auto points = PlanePoints(truth, centre, 1.0, 0.0, 200, rng);
  const PlaneFit fit = FitPlane(points);
  EXPECT_LT(NormalAngle(fit.plane.normal, truth.normal), 1e-10);
  EXPECT_LT(fit.rms_m, 1e-10);
}

TEST(FitPlane, NormalOrientedSoOffsetIsNonNegative) {
  const std::vector<Eigen::Vector3d> points = {
      {0.0, 0.0, -2.0}, {1.0, 0.0, -2.0}, {0.0, 1.0, -2.0}, {1.0, 1.0, -2.0}};
  const PlaneFit fit = FitPlane(points);
  EXPECT_NEAR(fit.plane.offset_m, 2.0, 1e-15);
  EXPECT_NEAR(fit.plane.normal.z(), -1.0, 1e-15);
}

TEST(FitPlane, ThrowsOnTooFewPoints) {
  const std::vector<Eigen::Vector3d> two = {{0.0, 0.0, 1.0}, {1.0, 0.0, 1.0}};
  EXPECT_THROW(FitPlane(two), Error);
  EXPECT_THROW(FitPlane({}), Error);
}

TEST(FitPlane, ThrowsOnCollinearOrCoincidentPoints) {
  std::vector<Eigen::Vector3d> line;
  const Eigen::Vector3d dir = Eigen::Vector3d(0.3, -0.4, 0.5).normalized();
  for (int i = 0; i < 10; ++i) {
    line.push_back(Eigen::Vector3d(1.0, 2.0, 3.0) + 0.37 * i * dir);
  }
  EXPECT_THROW(FitPlane(line), Error);
  // A thread 1e-12 m thick over 3 m is still a line.
  line[4] += 1e-12 * dir.unitOrthogonal();
  EXPECT_THROW(FitPlane(line), Error);
  const std::vector<Eigen::Vector3d> same(5, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_THROW(FitPlane(same), Error);
}

TEST(FitPlane, ThrowsOnNonFinitePoint) {
  std::vector<Eigen::Vector3d> points = {
      {0.0, 0.0, 1.0}, {1.0, 0.0, 1.0}, {0.0, 1.0, 1.0}, {1.0, 1.0, 1.0}};
  points[2].y() = kNaN;
  EXPECT_THROW(FitPlane(points), Error);
  points[2].y() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(FitPlane(points), Error);
}

TEST(FitPlane, ErrorMessageNamesTheProblem) {
  const std::vector<Eigen::Vector3d> two = {{0.0, 0.0, 1.0}, {1.0, 0.0, 1.0}};
  try {
    FitPlane(two);
    FAIL() << "expected uwscan::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("at least 3 points, got 2"), std::string::npos);
  }
}

TEST(IntersectRayPlane, HitLiesOnPlaneAndRay) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> coord(-2.0, 2.0);
  int hits = 0;
  for (int i = 0; i < 1000; ++i) {
    const Plane plane{RandomUnit(rng), coord(rng)};
    const Eigen::Vector3d origin = DrawVector3(coord, rng);
    const Ray ray{origin, RandomUnit(rng)};
    const RayHit hit = IntersectRayPlane(ray, plane);
    const double signed_distance = plane.normal.dot(ray.origin) - plane.offset_m;
    // Ahead exactly when the direction points towards the plane.
    const bool ahead = signed_distance * plane.normal.dot(ray.direction) < 0.0;
    ASSERT_EQ(hit.ok(), ahead);
    if (!hit.ok()) {
      EXPECT_EQ(hit.status, HitStatus::kBehind);
      continue;
    }
    ++hits;
    EXPECT_GE(hit.t, 0.0);
    EXPECT_NEAR(plane.normal.dot(hit.point), plane.offset_m, 1e-12 * (1.0 + hit.t));
    EXPECT_LT((hit.point - ray.At(hit.t)).norm(), 1e-15);
  }
  EXPECT_GT(hits, 300);
}

TEST(IntersectRayPlane, NonUnitDirectionScalesT) {
  const Plane plane{Eigen::Vector3d::UnitZ(), 2.0};
  const Ray unit{Eigen::Vector3d(0.1, 0.2, 0.5), Eigen::Vector3d(0.6, 0.0, 0.8)};
  const Ray scaled{unit.origin, 4.0 * unit.direction};
  const RayHit a = IntersectRayPlane(unit, plane);
  const RayHit b = IntersectRayPlane(scaled, plane);
  ASSERT_TRUE(a.ok());
  ASSERT_TRUE(b.ok());
  EXPECT_NEAR(a.t, 1.5 / 0.8, 1e-15);
  EXPECT_NEAR(b.t, a.t / 4.0, 1e-15);
  EXPECT_LT((a.point - b.point).norm(), 1e-15);
  EXPECT_NEAR(a.point.z(), 2.0, 1e-15);
}

TEST(IntersectRayPlane, ParallelRayIsReportedNotDividedBy) {
  const Plane plane{Eigen::Vector3d::UnitY(), 0.5};
  const Ray in_plane_direction{Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(1.0, 0.0, 0.0)};
  EXPECT_EQ(IntersectRayPlane(in_plane_direction, plane).status, HitStatus::kParallel);
  // 1e-13 rad off parallel is below the 1e-12 threshold; 1e-9 rad is a (far) hit.
  const Ray grazing{Eigen::Vector3d::Zero(), Eigen::Vector3d(1.0, 1e-13, 0.0)};
  EXPECT_EQ(IntersectRayPlane(grazing, plane).status, HitStatus::kParallel);
  const Ray shallow{Eigen::Vector3d::Zero(), Eigen::Vector3d(1.0, 1e-9, 0.0)};
  const RayHit far = IntersectRayPlane(shallow, plane);
  ASSERT_TRUE(far.ok());
  EXPECT_NEAR(far.t, 0.5e9, 1e-6);
  // The threshold is relative: a long direction vector does not change the answer.
  const Ray long_grazing{Eigen::Vector3d::Zero(), Eigen::Vector3d(1e6, 1e-7, 0.0)};
  EXPECT_EQ(IntersectRayPlane(long_grazing, plane).status, HitStatus::kParallel);
  const Ray zero{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  EXPECT_EQ(IntersectRayPlane(zero, plane).status, HitStatus::kParallel);
}

TEST(IntersectRayPlane, PlaneBehindOriginIsBehind) {
  const Plane plane{Eigen::Vector3d::UnitZ(), 1.0};
  const Ray away{Eigen::Vector3d(0.0, 0.0, 2.0), Eigen::Vector3d(0.0, 0.6, 0.8)};
  const RayHit hit = IntersectRayPlane(away, plane);
  EXPECT_EQ(hit.status, HitStatus::kBehind);
  EXPECT_TRUE(hit.point.allFinite());
}

TEST(IntersectRayPlane, OriginOnPlaneIsHitAtZero) {
  const Plane plane{Eigen::Vector3d::UnitZ(), 1.0};
  const Ray ray{Eigen::Vector3d(0.3, 0.0, 1.0), Eigen::Vector3d(0.0, 0.6, -0.8)};
  const RayHit hit = IntersectRayPlane(ray, plane);
  ASSERT_TRUE(hit.ok());
  EXPECT_EQ(hit.t, 0.0);
}

TEST(IntersectRayPlane, NaNInputIsNeverAHit) {
  const Plane plane{Eigen::Vector3d::UnitZ(), 1.0};
  const Ray nan_direction{Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, kNaN, 1.0)};
  const Ray nan_origin{Eigen::Vector3d(kNaN, 0.0, 0.0), Eigen::Vector3d::UnitZ()};
  const Ray nan_depth{Eigen::Vector3d(0.0, 0.0, kNaN), Eigen::Vector3d::UnitZ()};
  EXPECT_FALSE(IntersectRayPlane(nan_direction, plane).ok());
  EXPECT_FALSE(IntersectRayPlane(nan_origin, plane).ok());  // 0 * NaN is NaN: no shortcut
  EXPECT_FALSE(IntersectRayPlane(nan_depth, plane).ok());
  EXPECT_TRUE(IntersectRayPlane(nan_depth, plane).point.allFinite());
}

}  // namespace
}  // namespace uwscan::scanner
