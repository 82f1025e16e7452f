// A change report drawn: significant deviations in the diverging colours about zero (gained red,
// lost blue), everything else grey, a label per region; reports of other kinds refused.
#include "viewer/scene/change_report.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "mapping/change/change_report.hpp"
#include "scanner/common/atomic_file.hpp"
#include "scanner/common/error.hpp"
#include "viewer/scene/point_colours.hpp"
#include "viewer/scene/scene_files.hpp"

namespace uwscan::viewer {
namespace {

namespace fs = std::filesystem;

// Three core points: one gained 4 mm (significant, region 0), one lost 1 mm within its level of
// detection, one not inspected.
mapping::SurveyComparison ThreePoints() {
  mapping::SurveyComparison c;
  c.core_spacing_m = 0.01;
  const auto add = [&c](double x, double deviation, double lod, mapping::SurfaceStatus status,
                        int region) {
    mapping::CoreDeviation d;
    d.point_W = Eigen::Vector3d(x, 0.0, 10.0);
    d.normal_W = -Eigen::Vector3d::UnitZ();
    d.deviation_m = deviation;
    d.lod_m = lod;
    d.status = status;
    c.deviations.push_back(d);
    c.region_of.push_back(region);
  };
  add(0.0, 0.004, 0.001, mapping::SurfaceStatus::kChanged, 0);
  add(0.01, -0.001, 0.002, mapping::SurfaceStatus::kUnchanged, -1);
  add(0.02, NAN, NAN, mapping::SurfaceStatus::kNotInspected, -1);
  mapping::ChangeRegion r;
  r.core_indices = {0};
  r.centroid_W = c.deviations[0].point_W;
  r.area_m2 = 1e-4;
  r.mean_deviation_m = 0.004;
  c.regions.push_back(r);
  return c;
}

TEST(ChangeReport, SignificantDeviationsInDivergingColoursTheRestGreyARegionLabelled) {
  const fs::path folder =
      fs::temp_directory_path() / ("uwscan_change_report_" + std::to_string(getpid()));
  fs::create_directories(folder);
  const mapping::SurveyComparison c = ThreePoints();
  mapping::Survey map, reference;
  map.name = "after.json";
  reference.name = "before.json";
  mapping::WriteDeviationsPly(folder / "changes.ply", c);
  WriteFileAtomically(
      folder / "changes.json",
      mapping::ChangeReportJson(c, map, reference, {}, (folder / "changes.ply").string()).dump());
  ASSERT_EQ(KindOfFile(folder / "changes.json"), FileKind::kChangeReport);

  Scene scene;
  AddChangeReport(folder / "changes.json", scene);
  ASSERT_EQ(scene.clouds.size(), 1u);
  const CloudLayer& layer = scene.clouds.front();
  ASSERT_EQ(layer.deviation_m.size(), 3u);
  EXPECT_FLOAT_EQ(layer.deviation_m[0], 0.004f);
  EXPECT_TRUE(std::isnan(layer.deviation_m[1])) << "within its level of detection: grey";
  EXPECT_TRUE(std::isnan(layer.deviation_m[2])) << "not inspected: grey";
  EXPECT_NEAR((layer.Point(0) - Eigen::Vector3d(0, 0, 10)).norm(), 0.0, 1e-6);
  ASSERT_EQ(scene.labels.size(), 1u);
  EXPECT_EQ(scene.labels.front().text, "0: +4.0 mm, 1 cm2");

  RenderOptions options;
  options.colour = ColourMode::kDeviation;
  const std::vector<float> scalars = PointScalars(layer, options.colour, options.up, 1);
  const ScalarRange range = SceneRange({scalars, {-0.002f}}, options);
  EXPECT_DOUBLE_EQ(range.lo, -range.hi) << "symmetric about no change";
  const Rgb gained = PointColour(options.colour, scalars[0], range, 0, std::nullopt);
  const Rgb lost = PointColour(options.colour, -0.004f, range, 0, std::nullopt);
  EXPECT_GT(gained.r, gained.b + 100);
  EXPECT_GT(lost.b, lost.r + 100);
  EXPECT_EQ(PointColour(options.colour, scalars[1], range, 0, std::nullopt), kNoValue);

  // A PLY that is not the deviations file, and a report of another kind, are refused by name.
  std::ofstream(folder / "other.ply")
      << "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
         "property float y\nproperty float z\nend_header\n0 0 0\n";
  WriteFileAtomically(
      folder / "other.json",
      mapping::ChangeReportJson(c, map, reference, {}, (folder / "other.ply").string()).dump());
  Scene other;
  try {
    AddChangeReport(folder / "other.json", other);
    ADD_FAILURE() << "another PLY read as deviations";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("other.ply"), std::string::npos) << e.what();
  }
  fs::remove_all(folder);
}

}  // namespace
}  // namespace uwscan::viewer
