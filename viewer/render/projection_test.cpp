// The one world-to-picture projection, and the screenshot's pixels derived from it.
#include "viewer/render/projection.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "viewer/render/screenshot.hpp"

namespace uwscan::viewer {
namespace {

// A pinhole looking along +z: NDC = (x / z, y / z), w = z.
Eigen::Matrix4d PinholeAlongZ() {
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = 1.0;
  m(1, 1) = 1.0;
  m(2, 2) = 1.0;
  m(3, 2) = 1.0;
  return m;
}

TEST(NdcOf, DividesByDepthInFrontAndRefusesWhatIsBehindOrOutside) {
  const Eigen::Matrix4d camera = PinholeAlongZ();
  const std::optional<Eigen::Vector2d> ndc = NdcOf(camera, Eigen::Vector3d(1.0, -0.5, 2.0));
  ASSERT_TRUE(ndc.has_value());
  EXPECT_DOUBLE_EQ(ndc->x(), 0.5);
  EXPECT_DOUBLE_EQ(ndc->y(), -0.25);
  EXPECT_FALSE(NdcOf(camera, Eigen::Vector3d(1.0, -0.5, -2.0)));  // behind: mirrored otherwise
  EXPECT_FALSE(NdcOf(camera, Eigen::Vector3d(0.0, 0.0, 0.0)));    // on the camera
  EXPECT_FALSE(NdcOf(camera, Eigen::Vector3d(3.0, 0.0, 2.0)));    // right of the picture
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(NdcOf(camera, Eigen::Vector3d(nan, 0.0, 2.0)));
  EXPECT_TRUE(NdcOf(camera, Eigen::Vector3d(2.0, 2.0, 2.0)));  // the corner is inside
}

TEST(PictureInfo, PixelsCountFromTheTopLeftAndTheFarEdgeIsOutside) {
  PictureInfo info;
  info.width_px = 100;
  info.height_px = 50;
  info.ndc_from_world = PinholeAlongZ();
  EXPECT_EQ(info.PixelOf(Eigen::Vector3d(-1.0, 1.0, 1.0)), Eigen::Vector2i(0, 0));
  EXPECT_EQ(info.PixelOf(Eigen::Vector3d(0.999, -0.999, 1.0)), Eigen::Vector2i(99, 49));
  EXPECT_EQ(info.PixelOf(Eigen::Vector3d(0.0, 0.0, 1.0)), Eigen::Vector2i(50, 25));
  EXPECT_FALSE(info.PixelOf(Eigen::Vector3d(1.0, 0.0, 1.0)));  // x = 1: past the last column
  EXPECT_FALSE(info.PixelOf(Eigen::Vector3d(0.0, 0.0, -1.0)));
}

}  // namespace
}  // namespace uwscan::viewer
