#include "scanner/sim/imr_objects.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::sim {
namespace {

constexpr double kPi = std::numbers::pi;

// Every directed edge once and its reverse once: closed and consistently oriented.
bool Watertight(const TriangleMesh& mesh) {
  std::map<std::pair<int, int>, int> edges;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++edges[{t[k], t[(k + 1) % 3]}];
  }
  for (const auto& [edge, count] : edges) {
    if (count != 1) return false;
    const auto reverse = edges.find({edge.second, edge.first});
    if (reverse == edges.end() || reverse->second != 1) return false;
  }
  return true;
}

double EnclosedVolume(const TriangleMesh& mesh) {
  double six_volume = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    six_volume += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]]));
  }
  return six_volume / 6.0;
}

PipeShape DentedPipe(double depth_m) {
  PipeShape s;
  s.outer_radius_m = 0.08;
  s.wall_m = 0.008;
  s.length_m = 1.0;
  s.dent_radius_m = 0.03;
  s.dent_depth_m = depth_m;
  s.dent_angle_rad = 0.3;
  s.dent_position_m = -0.2;
  return s;
}

// The dent moves only the outer wall within its radius, inward by the profile it promises
// (depth (1 + cos(pi s / R)) / 2 at surface distance s), and takes away the volume of that
// profile: pi D R^2 (1/2 - 2/pi^2) on a flat wall, to within the wall's curvature.
TEST(ImrObjects, ADentedPipeDiffersFromItsUndentedTwinOnlyWithinTheDent) {
  const PipeShape s = DentedPipe(0.006);
  const TriangleMesh dented = MakePipe(s);
  const TriangleMesh twin = MakePipe(DentedPipe(0.0));
  ASSERT_EQ(dented.vertices.size(), twin.vertices.size());
  ASSERT_EQ(dented.triangles, twin.triangles);
  EXPECT_TRUE(Watertight(dented));
  double deepest = 0.0;
  int moved = 0;
  for (std::size_t i = 0; i < twin.vertices.size(); ++i) {
    const Eigen::Vector3d& v = twin.vertices[i];
    const double radius = v.head<2>().norm();
    const double turn = std::remainder(std::atan2(v.y(), v.x()) - s.dent_angle_rad, 2 * kPi);
    const double distance = std::hypot(s.outer_radius_m * turn, v.z() - s.dent_position_m);
    const bool outer = std::abs(radius - s.outer_radius_m) < 1e-9;
    const double expected = outer && distance < s.dent_radius_m
                                ? s.dent_depth_m * 0.5 * (1 + std::cos(kPi * distance / 0.03))
                                : 0.0;
    const double pressed = radius - dented.vertices[i].head<2>().norm();
    ASSERT_NEAR(pressed, expected, 1e-12) << i;
    EXPECT_EQ(dented.vertices[i].z(), v.z());
    deepest = std::max(deepest, pressed);
    moved += pressed > 0.0;
  }
  EXPECT_GT(moved, 100);
  EXPECT_GT(deepest, 0.95 * s.dent_depth_m);
  const double flat = kPi * s.dent_depth_m * 0.03 * 0.03 * (0.5 - 2.0 / (kPi * kPi));
  EXPECT_NEAR(EnclosedVolume(twin) - EnclosedVolume(dented), flat, 0.05 * flat);
}

TEST(ImrObjects, ADentMustFitTheWall) {
  PipeShape deep = DentedPipe(0.008);
  EXPECT_THROW(
      {
        try {
          MakePipe(deep);
        } catch (const Error& e) {
          EXPECT_NE(std::string(e.what()).find("dent_depth_m"), std::string::npos) << e.what();
          throw;
        }
      },
      Error);
  PipeShape off_the_end = DentedPipe(0.002);
  off_the_end.dent_position_m = 0.48;
  EXPECT_THROW(MakePipe(off_the_end), Error);
}

// A missing bolt head leaves its place on the flange bare and every other head where it was.
TEST(ImrObjects, AFlangeWithoutOneBoltHead) {
  FlangeShape full;
  FlangeShape missing = full;
  missing.missing_bolts = {3};
  const TriangleMesh with = MakeFlange(full), without = MakeFlange(missing);
  // A hexagonal prism: two rings of six and the centres of its ends.
  EXPECT_EQ(with.vertices.size() - without.vertices.size(), 14u);
  const double circle = 0.5 * (full.outer_radius_m + full.flange_radius_m);
  for (int k = 0; k < full.bolts; ++k) {
    const double angle = 2.0 * kPi * (k + 0.5) / full.bolts;
    const Eigen::Vector2d centre(circle * std::cos(angle), circle * std::sin(angle));
    int near = 0;
    for (const Eigen::Vector3d& v : without.vertices)
      near += (v.head<2>() - centre).norm() <= full.bolt_head_radius_m + 1e-9;
    if (k == 3) {
      EXPECT_EQ(near, 0);
    } else {
      EXPECT_EQ(near, 14) << k;
    }
  }
  missing.missing_bolts = {8};
  EXPECT_THROW(MakeFlange(missing), Error);
  missing.missing_bolts = {2, 2};
  EXPECT_THROW(MakeFlange(missing), Error);
}

}  // namespace
}  // namespace uwscan::scanner::sim
