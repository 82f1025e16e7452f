#include "perception/recognition/cloud_surface.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "perception/cloud/cloud_io.hpp"
#include "perception/recognition/object_catalogue.hpp"
#include "perception/recognition/object_symmetry.hpp"
#include "perception/recognition/recognition_test_support.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/triangle_mesh.hpp"
#include "scanner/sim/imr_objects.hpp"

namespace uwscan::perception {
namespace {

using namespace recognition_test;

// What a scan of `mesh` holds: points on its surface with noise of sigma_m, no normals.
PointCloud ScannedCloud(const scanner::TriangleMesh& mesh, int count, double sigma_m,
                        std::uint64_t seed) {
  return MakeCloud(scanner::ScannedSurface(mesh, count, sigma_m, seed));
}

// Each disc of a surface made from a sphere's scan faces out of it, and lies on it.
TEST(CloudSurface, TheDiscsOfAClosedObjectFaceOutwardsAndLieOnItsSurface) {
  const double radius_m = 0.1;
  const scanner::TriangleMesh surface =
      CloudSurface(ScannedCloud(scanner::sim::MakeUvSphere(radius_m), 20000, 0.0003, 1));
  ASSERT_GT(surface.triangles.size(), 1000u);
  std::size_t outward = 0, discs = 0;
  for (std::size_t t = 0; t < surface.triangles.size(); t += 6, ++discs) {  // 6 per disc
    const Eigen::Vector3i& tri = surface.triangles[t];
    const Eigen::Vector3d& a = surface.vertices[static_cast<std::size_t>(tri[0])];
    const Eigen::Vector3d n = (surface.vertices[static_cast<std::size_t>(tri[1])] - a)
                                  .cross(surface.vertices[static_cast<std::size_t>(tri[2])] - a);
    outward += n.dot(a) > 0.0;
    EXPECT_NEAR(a.norm(), radius_m, 0.002);
  }
  EXPECT_GE(static_cast<double>(outward), 0.99 * static_cast<double>(discs));
  EXPECT_THROW(CloudSurface(MakeCloud(std::vector<Eigen::Vector3d>(5, Eigen::Vector3d::Ones()))),
               Error);
}

// Inside a pipe's bore the outside is towards the axis: lines of sight leave through the ends,
// not through the wall. The bore's discs face the axis, the outer wall's face away from it (a rule
// such as "away from the centroid" gets the bore wrong).
TEST(CloudSurface, TheBoresDiscsFaceTheAxisAndTheOuterWallsFaceAway) {
  const scanner::sim::PipeShape shape;  // 50 mm outer radius, 5 mm wall, 0.5 m long
  const scanner::TriangleMesh surface =
      CloudSurface(ScannedCloud(scanner::sim::MakePipe(shape), 60000, 0.0002, 5));
  std::size_t bore = 0, bore_right = 0, outer = 0, outer_right = 0;
  for (std::size_t t = 0; t < surface.triangles.size(); t += 6) {
    const Eigen::Vector3i& tri = surface.triangles[t];
    const Eigen::Vector3d& a = surface.vertices[static_cast<std::size_t>(tri[0])];
    if (std::abs(a.z()) > 0.15) continue;  // the middle of its length
    const Eigen::Vector3d n = (surface.vertices[static_cast<std::size_t>(tri[1])] - a)
                                  .cross(surface.vertices[static_cast<std::size_t>(tri[2])] - a);
    const double radial = n.dot(Eigen::Vector3d(a.x(), a.y(), 0.0));
    const double r = std::hypot(a.x(), a.y());
    if (r < shape.outer_radius_m - 0.5 * shape.wall_m) {
      ++bore;
      bore_right += radial < 0.0;
    } else {
      ++outer;
      outer_right += radial > 0.0;
    }
  }
  ASSERT_GT(bore, 100u);
  ASSERT_GT(outer, 100u);
  EXPECT_GE(static_cast<double>(bore_right), 0.95 * static_cast<double>(bore));
  EXPECT_GE(static_cast<double>(outer_right), 0.99 * static_cast<double>(outer));
}

// An object taught from a scan of it (a cloud in a PLY without faces, 0.3 mm noise) is
// recognised, and posed, as the same object taught from its mesh is.
TEST(CloudSurface, AnObjectTaughtFromAScanIsRecognisedAsFromItsMesh) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  const ObjectSource flange = CatalogueObject("flange");
  const std::filesystem::path path = TestDir() / "scanned_flange.ply";
  WriteCloud(path, ScannedCloud(flange.mesh, 60000, 0.0003, 3));
  ASSERT_TRUE(IsCloudFile(path));
  std::vector<ObjectSource> sources = {CloudObject(path), CatalogueObject("pipe"),
                                       CatalogueObject("valve_wheel")};
  EXPECT_EQ(sources[0].id, "scanned_flange");
  DatabaseBuildOptions options;
  options.views = 16;
  options.threads = 2;
  const ObjectDatabase db = BuildObjectDatabase(sources, Scanner(), options);
  int recognised = 0, posed = 0;
  for (const Eigen::Vector3d& eye :
       {Eigen::Vector3d(0.35, 0.55, 0.55), Eigen::Vector3d(-0.35, 0.6, 0.5),
        Eigen::Vector3d(-0.5, -0.3, 0.7)}) {
    const Scan scan = ScanOnSeabed(flange.mesh, eye, 11);
    const RecognitionResult result = RecognizeObjects(scan.cloud, db);
    const RecognizedObject* found = Nearest(result, scan);
    ASSERT_NE(found, nullptr);
    if (found->object_id != "scanned_flange") continue;
    ++recognised;
    const SymmetricPoseError e =
        PoseErrorModuloSymmetry(found->T_S_O, scan.T_S_O, flange.mesh.vertices, *flange.symmetries);
    posed += e.rotation_rad < 2.0 * kDeg && e.translation_m < 0.005;
  }
  EXPECT_EQ(recognised, 3);
  // From (-0.5, -0.3, 0.7) the bolts' phase comes out a few degrees off about the axis (4.1 in
  // a first version), where the model taught from the mesh is 0.8 degrees off: the discs blur
  // the bolt heads' edges.
  EXPECT_GE(posed, 2);
}

}  // namespace
}  // namespace uwscan::perception
