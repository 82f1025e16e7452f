#include "viewer/scene/surface_error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::viewer::test {
namespace {

// A sphere of radius 0.2 m about (1, 2, 10): a point's distance to it is | |p - c| - r |.
scanner::sim::RayCaster SphereScene() {
  scanner::sim::SceneObject sphere;
  sphere.name = "ball";
  sphere.shape = scanner::sim::ObjectShape::kSphere;
  sphere.T_W_O.translation() = Eigen::Vector3d(1.0, 2.0, 10.0);
  sphere.sphere_radius_m = 0.2;
  return scanner::sim::RayCaster({sphere});
}

CloudLayer Layer(const std::string& name, const Eigen::Vector3d& origin,
                 const std::vector<Eigen::Vector3f>& points) {
  CloudLayer layer;
  layer.name = name;
  layer.origin = origin;
  layer.points = points;
  return layer;
}

TEST(SurfaceError, IsEachPointsDistanceToTheNearestTrueSurfaceAndNoValueBeyondTheSearch) {
  const scanner::sim::RayCaster truth = SphereScene();
  Scene scene;
  // Float offsets from a far origin, as maps are stored: outside, inside, on, and far from the
  // sphere.
  const Eigen::Vector3d origin(1.0, 2.0, 10.0);
  scene.clouds.push_back(
      Layer("map.ply", origin,
            {Eigen::Vector3f(0.203f, 0.0f, 0.0f), Eigen::Vector3f(0.0f, -0.19f, 0.0f),
             Eigen::Vector3f(0.0f, 0.0f, 0.2f), Eigen::Vector3f(0.0f, 0.0f, 1.5f)}));
  // A layer that already carries its own error (a dive log's, point by point) keeps it.
  CloudLayer own = Layer("dive.db", origin, {Eigen::Vector3f(0.5f, 0.0f, 0.0f)});
  own.error_m = {0.123f};
  scene.clouds.push_back(own);

  EXPECT_EQ(SetSurfaceError(truth, 0.5, scene), 1u);
  const std::vector<float>& e = scene.clouds[0].error_m;
  ASSERT_EQ(e.size(), 4u);
  for (std::size_t i = 0; i < 3; ++i) {
    const double exact = std::abs((scene.clouds[0].Point(i) - origin).norm() - 0.2);
    EXPECT_NEAR(e[i], exact, 1e-6) << "point " << i;
  }
  EXPECT_TRUE(std::isnan(e[3])) << "1.3 m from the sphere, beyond the 0.5 m search: " << e[3];
  ASSERT_EQ(scene.clouds[1].error_m.size(), 1u);
  EXPECT_EQ(scene.clouds[1].error_m[0], 0.123f);
}

TEST(SurfaceError, ABadSearchDistanceOrPointIsRefusedByName) {
  const scanner::sim::RayCaster truth = SphereScene();
  Scene scene;
  EXPECT_THROW(SetSurfaceError(truth, 0.0, scene), Error);
  scene.clouds.push_back(
      Layer("broken.ply", Eigen::Vector3d::Zero(), {Eigen::Vector3f(NAN, 0.0f, 0.0f)}));
  try {
    SetSurfaceError(truth, 0.5, scene);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("broken.ply"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace uwscan::viewer::test
