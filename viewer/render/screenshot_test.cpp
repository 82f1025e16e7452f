// Pictures of known scenes: colours where known points project, background elsewhere, the same
// bytes twice, and a stored baseline within tolerance.
#include "viewer/render/screenshot.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "scanner/common/error.hpp"
#include "viewer/plots/png_image.hpp"
#include "viewer/scene/colour_map.hpp"
#include "viewer/scene/point_colours.hpp"
#include "viewer/scene/scene_files.hpp"

namespace uwscan::viewer {
namespace {

namespace fs = std::filesystem;

fs::path TempPng(const std::string& name) {
  return fs::temp_directory_path() /
         ("uwscan_screenshot_test_" + std::to_string(::getpid()) + "_" + name + ".png");
}

std::string Bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A 5x5x5 lattice of points, 0.1 m apart, far from the world origin (as a dive's map is).
Scene CubeScene() {
  Scene scene;
  CloudLayer cube;
  cube.name = "cube";
  cube.origin = Eigen::Vector3d(1000.0, -2000.0, 50.0);
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 5; ++j) {
      for (int k = 0; k < 5; ++k)
        cube.points.emplace_back(0.1f * i - 0.2f, 0.1f * j - 0.2f, 0.1f * k - 0.2f);
    }
  }
  scene.clouds.push_back(cube);
  return scene;
}

RenderOptions SmallPicture(CameraPreset camera) {
  RenderOptions options;
  options.width_px = 320;
  options.height_px = 240;
  options.point_size_px = 7.0;
  options.camera = camera;
  options.colour_bar = false;
  return options;
}

bool Near(const Rgb& a, const Rgb& b, int tolerance) {
  return std::abs(a.r - b.r) <= tolerance && std::abs(a.g - b.g) <= tolerance &&
         std::abs(a.b - b.b) <= tolerance;
}

TEST(Screenshot, CubeOfPointsHasItsHeightColoursWherePointsProjectAndBackgroundElsewhere) {
  const Scene scene = CubeScene();
  for (const CameraPreset camera : {CameraPreset::kTop, CameraPreset::kSide, CameraPreset::kFit}) {
    const RenderOptions options = SmallPicture(camera);
    const fs::path png = TempPng("cube");
    const PictureInfo info = SaveScreenshot(scene, options, png);
    const RgbImage image = ReadPng(png);
    ASSERT_EQ(image.width_px, 320);
    ASSERT_EQ(image.height_px, 240);
    ASSERT_TRUE(info.range.has_value());
    const CloudLayer& cube = scene.clouds[0];
    const Eigen::Vector3d up = options.up.normalized();

    // Each point's expected colour, its pixel and its depth along the view.
    std::vector<Eigen::Vector2i> pixels;
    std::vector<double> depth;
    for (std::size_t i = 0; i < cube.size(); ++i) {
      const std::optional<Eigen::Vector2i> px = info.PixelOf(cube.Point(i));
      ASSERT_TRUE(px.has_value()) << "point " << i << " outside the picture";
      pixels.push_back(*px);
      const Eigen::Vector4d clip = info.ndc_from_world * cube.Point(i).homogeneous();
      depth.push_back(clip.z() / clip.w());
    }
    int checked = 0;
    for (std::size_t i = 0; i < cube.size(); ++i) {
      // A point covered by a nearer point's square may show that point's colour: skip it.
      bool covered = false;
      for (std::size_t j = 0; j < cube.size() && !covered; ++j) {
        covered =
            j != i && (pixels[j] - pixels[i]).cwiseAbs().maxCoeff() <= 8 && depth[j] < depth[i];
      }
      if (covered) continue;
      const Rgb expected = ContinuousColour(info.range->Normalise(up.dot(cube.Point(i))));
      const Rgb seen = image.At(pixels[i].x(), pixels[i].y());
      EXPECT_TRUE(Near(seen, expected, 3))
          << "point " << i << " at pixel " << pixels[i].transpose() << ": seen " << int(seen.r)
          << "," << int(seen.g) << "," << int(seen.b) << " expected " << int(expected.r) << ","
          << int(expected.g) << "," << int(expected.b);
      ++checked;
    }
    EXPECT_GE(checked, 9) << "too few visible points to check";

    // Every pixel farther than a point's half size from all points is background.
    int background = 0;
    for (int row = 0; row < image.height_px; row += 3) {
      for (int col = 0; col < image.width_px; col += 3) {
        bool near_point = false;
        for (const Eigen::Vector2i& p : pixels) {
          near_point = near_point || (p - Eigen::Vector2i(col, row)).cwiseAbs().maxCoeff() <= 6;
        }
        if (near_point) continue;
        EXPECT_EQ(image.At(col, row), options.background) << "pixel " << col << "," << row;
        ++background;
      }
    }
    EXPECT_GT(background, 1000);
    fs::remove(png);
  }
}

TEST(Screenshot, TrajectoryLineHasItsColourAlongItsSegments) {
  Scene scene;
  TrajectoryLayer path;
  path.name = "path";
  path.colour = Rgb{255, 127, 14};
  path.positions_W = {{10.0, 0.0, 5.0}, {11.0, 0.0, 5.0}, {11.0, 1.0, 5.0}, {12.0, 1.0, 5.2}};
  scene.trajectories.push_back(path);
  const RenderOptions options = SmallPicture(CameraPreset::kTop);
  const fs::path png = TempPng("trajectory");
  const PictureInfo info = SaveScreenshot(scene, options, png);
  const RgbImage image = ReadPng(png);
  for (std::size_t s = 0; s + 1 < path.positions_W.size(); ++s) {
    for (const double f : {0.25, 0.5, 0.75}) {
      const Eigen::Vector3d p = (1 - f) * path.positions_W[s] + f * path.positions_W[s + 1];
      const std::optional<Eigen::Vector2i> px = info.PixelOf(p);
      ASSERT_TRUE(px.has_value());
      EXPECT_EQ(image.At(px->x(), px->y()), *path.colour) << "segment " << s << " at " << f;
    }
  }
  EXPECT_EQ(image.At(2, 2), options.background);
  fs::remove(png);
}

TEST(Screenshot, TwoRunsGiveIdenticalFiles) {
  Scene scene = CubeScene();
  TrajectoryLayer path;
  path.positions_W = {{1000.0, -2000.0, 50.0}, {1000.3, -2000.0, 49.8}};
  scene.trajectories.push_back(path);
  RenderOptions options = SmallPicture(CameraPreset::kFit);
  options.colour_bar = true;
  options.eye_dome_lighting = true;
  const fs::path a = TempPng("first"), b = TempPng("second");
  SaveScreenshot(scene, options, a);
  SaveScreenshot(scene, options, b);
  const std::string first = Bytes(a);
  EXPECT_GT(first.size(), 100u);
  EXPECT_EQ(first, Bytes(b));
  fs::remove(a);
  fs::remove(b);
}

// The stored baseline: a cube and a trajectory with EDL and a colour bar. Regenerate it (after a
// deliberate change of the pictures) with UWSCAN_UPDATE_BASELINES=1.
TEST(Screenshot, MatchesTheStoredBaselineWithinTolerance) {
  Scene scene = CubeScene();
  TrajectoryLayer path;
  path.positions_W = {{999.7, -2000.3, 50.3}, {1000.3, -2000.3, 50.3}, {1000.3, -1999.7, 49.7}};
  scene.trajectories.push_back(path);
  RenderOptions options = SmallPicture(CameraPreset::kFit);
  options.colour_bar = true;
  options.eye_dome_lighting = true;
  const fs::path baseline =
      fs::path(UWSCAN_SOURCE_DIR_FOR_TESTS) / "viewer/testdata/cube_baseline.png";
  const char* update = std::getenv("UWSCAN_UPDATE_BASELINES");
  if (update != nullptr && std::string(update) == "1") SaveScreenshot(scene, options, baseline);
  const fs::path png = TempPng("baseline");
  SaveScreenshot(scene, options, png);
  const ImageDifference d = CompareImages(ReadPng(png), ReadPng(baseline), 40);
  // Another Mesa or FreeType may move an edge or a glyph by a pixel; not more.
  EXPECT_LT(d.mean_abs, 1.5);
  EXPECT_LT(d.fraction_over, 0.01);
  fs::remove(png);
}

TEST(Screenshot, DifferentSceneDoesNotMatchTheBaseline) {
  // The comparison can fail: the same cube seen from the side is far from the baseline.
  Scene scene = CubeScene();
  RenderOptions options = SmallPicture(CameraPreset::kSide);
  const fs::path png = TempPng("other");
  SaveScreenshot(scene, options, png);
  const fs::path baseline =
      fs::path(UWSCAN_SOURCE_DIR_FOR_TESTS) / "viewer/testdata/cube_baseline.png";
  const ImageDifference d = CompareImages(ReadPng(png), ReadPng(baseline), 40);
  EXPECT_GT(d.fraction_over, 0.01);
  fs::remove(png);
}

// A PLY with an intensity per point, read through the viewer's file loader and coloured by
// intensity over a fixed range: each point shows its own intensity's colour.
TEST(Screenshot, IntensityFromAPlyFileColoursEachPoint) {
  const fs::path ply = TempPng("intensity").replace_extension(".ply");
  std::vector<Eigen::Vector3d> grid;
  std::vector<float> intensity;
  {
    std::ofstream out(ply);
    out << "ply\nformat ascii 1.0\nelement vertex 25\nproperty double x\nproperty double y\n"
           "property double z\nproperty float intensity\nend_header\n";
    for (int i = 0; i < 5; ++i) {
      for (int j = 0; j < 5; ++j) {
        grid.emplace_back(0.2 * i, 0.2 * j, 3.0);  // a flat grid seen from above: nothing hidden
        intensity.push_back(static_cast<float>(10 * (i * 5 + j)));
        out << grid.back().x() << " " << grid.back().y() << " " << grid.back().z() << " "
            << intensity.back() << "\n";
      }
    }
  }
  Scene scene;
  AddFile(ply, mapping::ReconstructionOptions{}, MapReportDrawing{}, scene);
  fs::remove(ply);
  ASSERT_EQ(scene.clouds.size(), 1u);
  ASSERT_EQ(scene.clouds[0].intensity, intensity);

  RenderOptions options = SmallPicture(CameraPreset::kTop);
  options.colour = ColourMode::kIntensity;
  options.range = ScalarRange{0.0, 240.0};
  const fs::path png = TempPng("intensity");
  const PictureInfo info = SaveScreenshot(scene, options, png);
  const RgbImage image = ReadPng(png);
  fs::remove(png);
  for (std::size_t i = 0; i < grid.size(); ++i) {
    const std::optional<Eigen::Vector2i> px = info.PixelOf(grid[i]);
    ASSERT_TRUE(px.has_value()) << i;
    const Rgb expected = ContinuousColour(intensity[i] / 240.0);
    const Rgb seen = image.At(px->x(), px->y());
    EXPECT_TRUE(Near(seen, expected, 3))
        << "point " << i << ": seen " << int(seen.r) << "," << int(seen.g) << "," << int(seen.b)
        << " expected " << int(expected.r) << "," << int(expected.g) << "," << int(expected.b);
  }
}

TEST(Screenshot, ErrorColouringOfACloudWithoutTruthNamesTheLayer) {
  RenderOptions options = SmallPicture(CameraPreset::kFit);
  options.colour = ColourMode::kError;
  try {
    SaveScreenshot(CubeScene(), options, TempPng("error"));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cube"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace uwscan::viewer
