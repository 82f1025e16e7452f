#include "scanner/sim/ray_caster.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/sim/imr_objects.hpp"

namespace uwscan::scanner::sim {
namespace {

constexpr double kPi = std::numbers::pi;

Eigen::Isometry3d Pose(const Eigen::Vector3d& t,
                       const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

SceneObject MeshObject(std::string name, ObjectShape shape, TriangleMesh mesh,
                       const Eigen::Isometry3d& T_W_O, double reflectance) {
  SceneObject o;
  o.name = std::move(name);
  o.shape = shape;
  o.mesh = std::move(mesh);
  o.T_W_O = T_W_O;
  o.reflectance = reflectance;
  return o;
}

SceneObject Sphere(const Eigen::Vector3d& centre, double radius, double reflectance = 0.5) {
  SceneObject o;
  o.name = "sphere";
  o.shape = ObjectShape::kSphere;
  o.sphere_radius_m = radius;
  o.T_W_O = Pose(centre);
  o.reflectance = reflectance;
  return o;
}

// A 3 m x 3 m plane at z = depth facing the origin (its +z_O turned to -z_W).
SceneObject Backdrop(double depth, double reflectance = 0.3) {
  return MeshObject(
      "seabed", ObjectShape::kPlane, MakeRectangle(3.0, 3.0),
      Pose({0.0, 0.0, depth}, Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitX()).matrix()),
      reflectance);
}

// Random unit directions within `half_angle` of +z.
std::vector<Eigen::Vector3d> Directions(int count, double half_angle, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-std::tan(half_angle), std::tan(half_angle));
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < count; ++i) out.push_back(Eigen::Vector3d{u(rng), u(rng), 1.0}.normalized());
  return out;
}

TEST(RayCaster, PlaneHitsAreExactInDouble) {
  const RayCaster caster({Backdrop(1.3, 0.25)});
  for (const Eigen::Vector3d& d : Directions(500, 0.6, 1)) {
    const std::optional<SurfaceHit> hit = caster.Cast({Eigen::Vector3d::Zero(), d});
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->point_W.z(), 1.3, 1e-12 * 1.3);
    EXPECT_NEAR(hit->distance_m, 1.3 / d.z(), 1e-12 * hit->distance_m);
    EXPECT_LT((hit->normal_W - Eigen::Vector3d(0, 0, -1)).norm(), 1e-15);
    EXPECT_EQ(hit->object_index, 0);
    EXPECT_EQ(hit->reflectance, 0.25);
  }
}

TEST(RayCaster, TiltedPlaneFromAfar) {
  // A plane in a general pose, rays from ~3 m away: the hit lies on the plane to 1e-12.
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized())).matrix();
  const Eigen::Isometry3d T_W_O = Pose({0.3, -0.2, 1.1}, R);
  const RayCaster caster(
      {MeshObject("plate", ObjectShape::kPlane, MakeRectangle(1.0, 1.0), T_W_O, 0.5)});
  const Eigen::Vector3d n = R.col(2), p0 = T_W_O.translation();
  const Eigen::Vector3d origin = p0 + Eigen::Vector3d(1.0, 2.0, -2.0);
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-0.45, 0.45);
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3d target = T_W_O * Eigen::Vector3d{u(rng), u(rng), 0.0};
    const std::optional<SurfaceHit> hit = caster.Cast({origin, target - origin});
    ASSERT_TRUE(hit);
    EXPECT_LE(std::abs(n.dot(hit->point_W - p0)), 1e-12);
    EXPECT_LE((hit->point_W - target).norm(), 1e-12 * (target - origin).norm());
    EXPECT_LT((hit->normal_W - n).norm(), 1e-12);
  }
  // Past the edge: a miss.
  const Eigen::Vector3d outside = T_W_O * Eigen::Vector3d(0.51, 0.0, 0.0);
  EXPECT_FALSE(caster.Cast({origin, outside - origin}));
}

TEST(RayCaster, SphereHitsAreExactInDouble) {
  const Eigen::Vector3d c(0.05, -0.02, 1.0);
  const double r = 0.1;
  const RayCaster caster({Sphere(c, r, 0.7)});
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const Eigen::Vector3d& origin : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1.5, 2.0, -1.0),
                                        Eigen::Vector3d(-2.0, 0.3, 3.5)}) {
    for (int i = 0; i < 300; ++i) {
      // Aim at points within 0.99 r of the centre across the line of sight.
      Eigen::Vector3d offset{u(rng), u(rng), u(rng)};
      offset *= 0.99 * r / std::max(1.0, offset.norm());
      const Eigen::Vector3d d = (c + offset - origin).normalized();
      const std::optional<SurfaceHit> hit = caster.Cast({origin, d});
      ASSERT_TRUE(hit);
      EXPECT_LE(std::abs((hit->point_W - c).norm() - r), 1e-12 * r);
      EXPECT_LE((hit->point_W - (origin + hit->distance_m * d)).norm(), 1e-14);
      EXPECT_LT((hit->normal_W - (hit->point_W - c) / r).norm(), 1e-14);
      EXPECT_GT(hit->normal_W.dot(-d), 0.0);  // the near side
      EXPECT_EQ(hit->reflectance, 0.7);
    }
  }
  // Grazing by a nanometre either side of the silhouette.
  const Eigen::Vector3d side = c + Eigen::Vector3d(r + 1e-9, 0.0, 0.0);
  EXPECT_FALSE(caster.Cast({side - Eigen::Vector3d(0, 0, 2), Eigen::Vector3d::UnitZ()}));
  const Eigen::Vector3d inside = c + Eigen::Vector3d(r - 1e-9, 0.0, 0.0);
  EXPECT_TRUE(caster.Cast({inside - Eigen::Vector3d(0, 0, 2), Eigen::Vector3d::UnitZ()}));
}

TEST(RayCaster, DirectionNeedNotBeUnit) {
  const RayCaster caster({Sphere({0.0, 0.0, 1.0}, 0.1)});
  const std::optional<SurfaceHit> unit = caster.Cast({Eigen::Vector3d::Zero(), {0.01, 0.0, 1.0}});
  const std::optional<SurfaceHit> long_ray =
      caster.Cast({Eigen::Vector3d::Zero(), Eigen::Vector3d(0.01, 0.0, 1.0) * 3.7});
  ASSERT_TRUE(unit && long_ray);
  EXPECT_NEAR(unit->distance_m, long_ray->distance_m, 1e-15);
  EXPECT_NEAR(unit->distance_m, (unit->point_W).norm(), 1e-15);
  // The range is metric too: t_max_m just short of the surface misses it.
  EXPECT_FALSE(
      caster.Cast({Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 0.0, 5.0)}, 0.0, 0.9 - 1e-9));
  EXPECT_TRUE(
      caster.Cast({Eigen::Vector3d::Zero(), Eigen::Vector3d(0.0, 0.0, 5.0)}, 0.0, 0.9 + 1e-12));
}

TEST(RayCaster, RaysStartingOnASurface) {
  const Eigen::Vector3d c(0.0, 0.0, 1.0);
  const double r = 0.1;
  const RayCaster caster({Sphere(c, r), Backdrop(1.3)});
  const Eigen::Vector3d n = Eigen::Vector3d(0.3, -0.5, -0.8).normalized();
  const Eigen::Vector3d on = c + r * n;
  // Leaving the sphere outward (towards the origin side): nothing else in the way.
  EXPECT_FALSE(caster.Cast({on, n}, 1e-9));
  // With t_min = 0 the surface the ray starts on is found at distance ~0.
  const std::optional<SurfaceHit> self = caster.Cast({on, n});
  if (self) {
    EXPECT_LE(self->distance_m, 1e-15);
  }
  // Into the sphere: the far side, at the chord length 2 r cos(incidence).
  const Eigen::Vector3d inward = (-n + 0.4 * n.unitOrthogonal()).normalized();
  const std::optional<SurfaceHit> through = caster.Cast({on, inward}, 1e-9);
  ASSERT_TRUE(through);
  EXPECT_EQ(through->object_index, 0);
  EXPECT_NEAR(through->distance_m, 2.0 * r * inward.dot(-n), 1e-14);
  // From the plane back towards the origin, missing the sphere.
  const Eigen::Vector3d on_plane(0.5, 0.2, 1.3);
  EXPECT_FALSE(caster.Cast({on_plane, -on_plane}, 1e-9));
  // Into the plane from on it (two-sided, zero thickness): nothing behind it.
  EXPECT_FALSE(caster.Cast({on_plane, Eigen::Vector3d::UnitZ()}, 1e-9));
}

TEST(RayCaster, BoxFacesAndNormals) {
  const Eigen::Vector3d size(0.2, 0.3, 0.4);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 1.0, -0.4).normalized()).matrix();
  const Eigen::Isometry3d T_W_O = Pose({0.1, 0.05, 1.2}, R);
  const RayCaster caster({MeshObject("box", ObjectShape::kBox, MakeBox(size), T_W_O, 0.5)});
  const Eigen::Isometry3d T_O_W = T_W_O.inverse();
  int hits = 0;
  for (const Eigen::Vector3d& d : Directions(400, 0.15, 4)) {
    const Eigen::Vector3d origin(0.0, 0.0, -1.0);
    const std::optional<SurfaceHit> hit = caster.Cast({origin, d});
    if (!hit) continue;
    ++hits;
    const Eigen::Vector3d p_O = T_O_W * hit->point_W;
    const Eigen::Array3d ratio = p_O.cwiseQuotient(0.5 * size).array().abs();
    int face = 0;
    ratio.maxCoeff(&face);
    EXPECT_NEAR(ratio[face], 1.0, 1e-12);
    EXPECT_LE(ratio.maxCoeff(), 1.0 + 1e-12);
    Eigen::Vector3d n_O = Eigen::Vector3d::Zero();
    n_O[face] = p_O[face] > 0.0 ? 1.0 : -1.0;
    EXPECT_LT((hit->normal_W - R * n_O).norm(), 1e-12);
    EXPECT_LT(hit->normal_W.dot(d), 0.0);  // an outside face seen from outside
  }
  EXPECT_GT(hits, 50);
}

// Distance from p to an axis-aligned box of half-size h centred at the origin (exact formula).
double BoxDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& h) {
  const Eigen::Vector3d q = p.cwiseAbs() - h;
  const double outside = q.cwiseMax(0.0).norm();
  const double inside = std::min(q.maxCoeff(), 0.0);
  return outside > 0.0 ? outside : -inside;
}

TEST(RayCaster, DistanceToSurfaceMatchesExactFormulas) {
  const Eigen::Vector3d size(0.2, 0.3, 0.4);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 1.0, -0.4).normalized()).matrix();
  const Eigen::Isometry3d T_W_O = Pose({0.1, 0.05, 1.2}, R);
  const Eigen::Vector3d centre(-0.6, 0.2, 1.0);
  const RayCaster caster(
      {MeshObject("box", ObjectShape::kBox, MakeBox(size), T_W_O, 0.5), Sphere(centre, 0.15)});
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int found = 0;
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3d p{u(rng), u(rng), 1.1 + 0.5 * u(rng)};
    const double box = BoxDistance(T_W_O.inverse() * p, 0.5 * size);
    const double sphere = std::abs((p - centre).norm() - 0.15);
    const double expected = std::min(box, sphere);
    const std::optional<double> d = caster.DistanceToSurface(p, 0.3);
    if (expected <= 0.3 - 1e-9) {
      ASSERT_TRUE(d.has_value()) << "point " << i;
      EXPECT_NEAR(*d, expected, 1e-12);
      ++found;
    } else if (expected > 0.3 + 1e-9) {
      EXPECT_FALSE(d.has_value()) << "point " << i;
    }
  }
  EXPECT_GT(found, 100);
  EXPECT_THROW(caster.DistanceToSurface(Eigen::Vector3d::Constant(NAN), 1.0), Error);
  EXPECT_THROW(caster.DistanceToSurface(Eigen::Vector3d::Zero(), 0.0), Error);
}

TEST(RayCaster, CylinderMeshWithinTheChordError) {
  const double r = 0.1, chord = 1e-4;
  const RayCaster caster({MeshObject("cylinder", ObjectShape::kCylinder,
                                     MakeCylinder(r, 0.5, chord), Pose({0.0, 0.0, 1.0}), 0.5)});
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> x(-0.099, 0.099), z(-0.24, 0.24);
  for (int i = 0; i < 500; ++i) {
    // Rays across the axis (which is z), from 2 m away along y.
    const Eigen::Vector3d origin{x(rng), -2.0, 1.0 + z(rng)};
    const std::optional<SurfaceHit> hit = caster.Cast({origin, Eigen::Vector3d::UnitY()});
    ASSERT_TRUE(hit);
    const double radius = hit->point_W.head<2>().norm();
    EXPECT_LE(radius, r + 1e-12);
    EXPECT_GE(radius, r - chord - 1e-12);
    EXPECT_NEAR(hit->point_W.x(), origin.x(), 1e-12);
  }
}

TEST(RayCaster, NearestOfSeveralObjects) {
  const Eigen::Isometry3d box_pose = Pose({0.0, 0.0, 0.8});
  const RayCaster caster(
      {Backdrop(1.3, 0.1), Sphere({0.0, 0.0, 1.0}, 0.1, 0.2),
       MeshObject("box", ObjectShape::kBox, MakeBox({0.05, 0.05, 0.05}), box_pose, 0.3)});
  const Ray ray{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()};
  std::vector<std::pair<int, double>> seen;
  double t = 0.0;
  while (const std::optional<SurfaceHit> hit = caster.Cast(ray, t + 1e-9)) {
    seen.emplace_back(hit->object_index, hit->distance_m);
    EXPECT_EQ(hit->reflectance, hit->object_index == 0 ? 0.1 : hit->object_index == 1 ? 0.2 : 0.3);
    t = hit->distance_m;
  }
  const std::vector<std::pair<int, double>> expected = {
      {2, 0.775}, {2, 0.825}, {1, 0.9}, {1, 1.1}, {0, 1.3}};
  ASSERT_EQ(seen.size(), expected.size());
  for (size_t i = 0; i < seen.size(); ++i) {
    EXPECT_EQ(seen[i].first, expected[i].first) << i;
    EXPECT_NEAR(seen[i].second, expected[i].second, 1e-15) << i;
  }
  // A ray beside the box and the sphere reaches the backdrop.
  const std::optional<SurfaceHit> side = caster.Cast({Eigen::Vector3d::Zero(), {0.3, 0.0, 1.0}});
  ASSERT_TRUE(side);
  EXPECT_EQ(side->object_index, 0);
  // Beyond everything: a miss.
  EXPECT_FALSE(caster.Cast({Eigen::Vector3d::Zero(), {3.0, 0.0, 1.0}}));
  EXPECT_FALSE(caster.Cast({Eigen::Vector3d::Zero(), -Eigen::Vector3d::UnitZ()}));
}

TEST(RayCaster, BlockedBetweenTwoPoints) {
  const Eigen::Vector3d c(0.0, 0.0, 1.0);
  const RayCaster caster({Backdrop(1.3), Sphere(c, 0.1)});
  const Eigen::Vector3d camera = Eigen::Vector3d::Zero();
  EXPECT_TRUE(caster.Blocked(camera, {0.0, 0.0, 1.3}));   // the sphere is in front
  EXPECT_FALSE(caster.Blocked(camera, {0.4, 0.0, 1.3}));  // beside it
  // From the sphere's near side to the camera: clear; from its far side: the sphere itself.
  EXPECT_FALSE(caster.Blocked(c - Eigen::Vector3d(0, 0, 0.1), camera));
  EXPECT_TRUE(caster.Blocked(c + Eigen::Vector3d(0.05, 0.0, std::sqrt(0.0075)), camera));
  // A laser spot on the backdrop seen from a camera beside it: clear.
  EXPECT_FALSE(caster.Blocked({0.3, 0.0, 0.0}, {0.5, 0.0, 1.3}));
  // Segments too short to hold anything.
  EXPECT_FALSE(caster.Blocked(camera, camera));
  EXPECT_FALSE(caster.Blocked(camera, {0.0, 0.0, 1e-6}, 1e-6));
  // A point on the backdrop looking through it stays blocked only by what lies between.
  EXPECT_FALSE(caster.Blocked({0.0, 0.5, 1.3}, {0.0, 0.5, 2.0}));
  EXPECT_TRUE(caster.Blocked({0.0, 0.5, 1.0}, {0.0, 0.5, 2.0}));
}

// Coordinates far from the world origin (a vehicle kilometres into its dive): Embree works
// relative to the objects, and the exact refinement keeps double precision.
TEST(RayCaster, FarFromTheWorldOrigin) {
  const Eigen::Vector3d offset(1200.0, -2500.0, 40.0);
  const Eigen::Vector3d c = offset + Eigen::Vector3d(0.0, 0.0, 1.0);
  const RayCaster caster({Sphere(c, 0.1)});
  for (const Eigen::Vector3d& d : Directions(300, 0.09, 6)) {
    const std::optional<SurfaceHit> hit = caster.Cast({offset, d});
    if (!hit) {
      // Only rays that truly miss.
      EXPECT_GT((c - offset).cross(d).norm(), 0.1 - 1e-12);
      continue;
    }
    EXPECT_LE(std::abs((hit->point_W - c).norm() - 0.1), 1e-11);
  }
}

TEST(RayCaster, ConcurrentCastsMatchSerial) {
  const RayCaster caster(
      {Backdrop(1.3), Sphere({0.0, 0.0, 1.0}, 0.1),
       MeshObject(
           "pipe", ObjectShape::kPipe, MakePipe({}),
           Pose({0.1, 0.1, 0.9}, Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitY()).matrix()),
           0.4)});
  const std::vector<Eigen::Vector3d> directions = Directions(20000, 0.5, 7);
  std::vector<double> serial(directions.size()), parallel(directions.size());
  for (size_t i = 0; i < directions.size(); ++i) {
    const auto hit = caster.Cast({Eigen::Vector3d::Zero(), directions[i]});
    serial[i] = hit ? hit->distance_m + 10.0 * hit->object_index : -1.0;
  }
#pragma omp parallel for schedule(dynamic, 64)
  for (int i = 0; i < static_cast<int>(directions.size()); ++i) {
    const auto hit = caster.Cast({Eigen::Vector3d::Zero(), directions[i]});
    parallel[i] = hit ? hit->distance_m + 10.0 * hit->object_index : -1.0;
  }
  EXPECT_EQ(serial, parallel);
}

TEST(RayCaster, EmptySceneAndBadInput) {
  const RayCaster empty({});
  EXPECT_EQ(empty.object_count(), 0);
  EXPECT_FALSE(empty.Cast({Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()}));
  EXPECT_FALSE(empty.Blocked(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()));

  const RayCaster caster({Sphere({0, 0, 1}, 0.1)});
  EXPECT_THROW(caster.Cast({Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()}), Error);
  EXPECT_THROW(caster.Cast({Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()}, -1.0), Error);
  EXPECT_THROW(caster.Cast({Eigen::Vector3d(std::nan(""), 0, 0), Eigen::Vector3d::UnitZ()}), Error);

  SceneObject no_mesh;
  no_mesh.name = "nothing";
  no_mesh.shape = ObjectShape::kBox;
  EXPECT_THROW(RayCaster({no_mesh}), Error);
  EXPECT_THROW(RayCaster({Sphere({0, 0, 1}, 0.0)}), Error);

  // Movable.
  RayCaster moved = RayCaster({Sphere({0, 0, 1}, 0.1)});
  EXPECT_TRUE(moved.Cast({Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ()}));
}

}  // namespace
}  // namespace uwscan::scanner::sim
