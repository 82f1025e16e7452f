// A recognition report drawn over its scan: the segment and the model placed at the reported
// pose share the object's colour, the rest of the scan is grey, the grasp frame shows its axes'
// colours, and broken reports are refused naming the field.
#include "viewer/scene/recognition_report.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "perception/cloud/cloud_io.hpp"
#include "perception/recognition/object_database.hpp"
#include "scanner/common/error.hpp"
#include "viewer/plots/png_image.hpp"
#include "viewer/render/screenshot.hpp"
#include "viewer/scene/scene_files.hpp"

namespace uwscan::viewer {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json Matrix(const Eigen::Isometry3d& T) {
  json rows = json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({T(r, 0), T(r, 1), T(r, 2), T(r, 3)});
  return rows;
}

bool Near(const Rgb& a, const Rgb& b, int tolerance) {
  return std::abs(a.r - b.r) <= tolerance && std::abs(a.g - b.g) <= tolerance &&
         std::abs(a.b - b.b) <= tolerance;
}

// A flat 10 cm square object ("tile") in a database file, a scan of it lying on a wall 20 cm
// behind it, and the report `uwscan recognize --json` would write for that scan.
class RecognitionReportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("uwscan_recognition_report_test_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    T_S_O_.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T_S_O_.translation() = Eigen::Vector3d(0.25, -0.1, 0.8);
    // The gripper 5 cm in front of the tile (towards the sensor), approaching along +z_S.
    T_S_G_ = T_S_O_ * Eigen::Translation3d(0.0, 0.0, -0.05);

    perception::ObjectModel tile;
    tile.id = "tile";
    tile.source = "made by the test";
    std::vector<Eigen::Vector3d> model_points;
    for (int i = 0; i < 5; ++i) {
      for (int j = 0; j < 5; ++j)
        model_points.emplace_back(0.025 * i - 0.05, 0.025 * j - 0.05, 0.0);
    }
    tile.model = perception::MakeCloud(model_points);
    tile.model.normals.assign(model_points.size(), Eigen::Vector3f(0.0f, 0.0f, -1.0f));
    tile.diameter_m = std::sqrt(2.0) * 0.1;
    perception::ObjectDatabase db;
    db.objects.push_back(tile);
    db.Save(dir_ / "objects.db");

    std::vector<Eigen::Vector3d> scan_points;
    for (int i = 0; i < 9; ++i) {
      for (int j = 0; j < 9; ++j) scan_points.emplace_back(0.12 * i - 0.48, 0.12 * j - 0.48, 1.0);
    }
    json segment = json::array();
    for (const Eigen::Vector3d& p : model_points) {
      segment.push_back(scan_points.size());
      scan_points.push_back(T_S_O_ * p);
      model_S_.push_back(scan_points.back());
    }
    wall_S_.assign(scan_points.begin(), scan_points.begin() + 81);
    perception::WriteCloud(dir_ / "scan.ply", perception::MakeCloud(scan_points));

    report_ = {{"uwscan_format", 1},
               {"kind", "recognition_report"},
               {"scan", "scan.ply"},
               {"database", "objects.db"},
               {"scan_points", scan_points.size()},
               {"objects",
                {{{"id", "tile"},
                  {"points", segment.size()},
                  {"segment", segment},
                  {"centroid_m", {0.25, -0.1, 0.8}},
                  {"score", 0.87},
                  {"T_S_O", {{"matrix", Matrix(T_S_O_)}}},
                  {"grasps", {{{"name", "face"}, {"matrix", Matrix(T_S_G_)}}}}}}}};
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path Write(const json& report, const std::string& name = "report.json") {
    const fs::path path = dir_ / name;
    std::ofstream(path) << report.dump();
    return path;
  }

  std::string ErrorOf(const json& report) {
    try {
      Scene scene;
      AddFile(Write(report, "bad.json"), mapping::ReconstructionOptions{}, MapReportDrawing{},
              scene);
    } catch (const Error& e) {
      return e.what();
    }
    return "(no error)";
  }

  fs::path dir_;
  Eigen::Isometry3d T_S_O_ = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_S_G_ = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector3d> model_S_, wall_S_;
  json report_;
};

TEST_F(RecognitionReportTest, ReadsWhatRecognizeWrites) {
  const RecognitionReport r = ReadRecognitionReport(Write(report_));
  EXPECT_EQ(r.scan, dir_ / "scan.ply");  // relative to the report's folder
  EXPECT_EQ(r.database, dir_ / "objects.db");
  EXPECT_EQ(r.scan_points, 81u + 25u);
  ASSERT_EQ(r.objects.size(), 1u);
  EXPECT_EQ(r.objects[0].id, "tile");
  EXPECT_EQ(r.objects[0].segment.size(), 25u);
  EXPECT_TRUE(r.objects[0].T_S_O.isApprox(T_S_O_, 1e-12));
  ASSERT_EQ(r.objects[0].grasps_S.size(), 1u);
  EXPECT_EQ(r.objects[0].grasps_S[0].first, "face");
}

TEST_F(RecognitionReportTest, SegmentAndModelShareTheObjectsColourAndTheGraspShowsItsAxes) {
  Scene scene;
  AddFile(Write(report_), mapping::ReconstructionOptions{}, MapReportDrawing{}, scene);
  ASSERT_EQ(scene.clouds.size(), 2u);  // the scan, the placed model
  ASSERT_EQ(scene.frames.size(), 1u);
  ASSERT_EQ(scene.labels.size(), 1u);
  EXPECT_EQ(scene.labels[0].text, "tile 0.87");
  for (std::size_t i = 0; i < model_S_.size(); ++i) {
    EXPECT_LT((scene.clouds[1].Point(i) - model_S_[i]).norm(), 1e-6)
        << "model point " << i << " not at the pose";
  }
  // The segment's points (after the 81 wall points) carry the object's index; the wall none.
  const std::vector<std::int32_t>& ids = scene.clouds[0].object_ids;
  ASSERT_EQ(ids.size(), 81u + 25u);
  for (std::size_t i = 0; i < ids.size(); ++i)
    EXPECT_EQ(ids[i], i < 81 ? -1 : 0) << "scan point " << i;

  RenderOptions options;
  options.width_px = 400;
  options.height_px = 400;
  options.point_size_px = 5.0;
  options.colour = ColourMode::kObject;
  options.camera = CameraPreset::kTop;  // along the scan's +z, as the sensor looked
  options.up = Eigen::Vector3d(0.0, 0.0, -1.0);
  scene.labels.clear();  // text over the object would hide the colours checked here
  const fs::path png = dir_ / "report.png";
  const PictureInfo info = SaveScreenshot(scene, options, png);
  const RgbImage image = ReadPng(png);

  int wall_seen = 0;
  for (const Eigen::Vector3d& p : wall_S_) {
    const std::optional<Eigen::Vector2i> px = info.PixelOf(p);
    ASSERT_TRUE(px.has_value());
    // Wall points not under the tile show "no object".
    bool under_tile = false;
    for (const Eigen::Vector3d& m : model_S_) {
      const std::optional<Eigen::Vector2i> q = info.PixelOf(m);
      under_tile = under_tile || (q && (*q - *px).cwiseAbs().maxCoeff() <= 6);
    }
    if (under_tile) continue;
    EXPECT_TRUE(Near(image.At(px->x(), px->y()), kNoValue, 2))
        << "wall point at " << px->transpose();
    ++wall_seen;
  }
  EXPECT_GT(wall_seen, 60);
  const Eigen::Vector3d x_axis_middle =
      T_S_G_ * Eigen::Vector3d(0.5 * scene.frames[0].length_m, 0.0, 0.0);
  const Eigen::Vector3d y_axis_middle =
      T_S_G_ * Eigen::Vector3d(0.0, 0.5 * scene.frames[0].length_m, 0.0);
  for (const Eigen::Vector3d& m : model_S_) {
    const std::optional<Eigen::Vector2i> px = info.PixelOf(m);
    ASSERT_TRUE(px.has_value());
    // The grasp's lines lie over some tile points; those are checked below.
    const auto on_axis = [&](const Eigen::Vector3d& a) {
      return (info.PixelOf(a).value() - *px).cwiseAbs().maxCoeff() <= 12;
    };
    if (on_axis(x_axis_middle) || on_axis(y_axis_middle) || on_axis(T_S_G_.translation())) continue;
    EXPECT_TRUE(Near(image.At(px->x(), px->y()), CategoricalColour(0), 2))
        << "tile point at " << px->transpose();
  }
  const Eigen::Vector2i x_px = info.PixelOf(x_axis_middle).value();
  const Eigen::Vector2i y_px = info.PixelOf(y_axis_middle).value();
  EXPECT_TRUE(Near(image.At(x_px.x(), x_px.y()), Rgb{230, 25, 25}, 2));
  EXPECT_TRUE(Near(image.At(y_px.x(), y_px.y()), Rgb{25, 200, 25}, 2));
}

TEST_F(RecognitionReportTest, TheLabelIsDrawn) {
  Scene scene;
  AddFile(Write(report_), mapping::ReconstructionOptions{}, MapReportDrawing{}, scene);
  RenderOptions options;
  options.width_px = 400;
  options.height_px = 400;
  options.colour = ColourMode::kObject;
  options.camera = CameraPreset::kFit;  // oblique: the label stands in front of the tile
  options.up = Eigen::Vector3d(0.0, 0.0, -1.0);
  SaveScreenshot(scene, options, dir_ / "with.png");
  scene.labels.clear();
  SaveScreenshot(scene, options, dir_ / "without.png");
  const RgbImage with = ReadPng(dir_ / "with.png"), without = ReadPng(dir_ / "without.png");
  int changed = 0;
  for (int row = 0; row < with.height_px; ++row) {
    for (int col = 0; col < with.width_px; ++col)
      changed += !(with.At(col, row) == without.At(col, row));
  }
  EXPECT_GT(changed, 30) << "the label's text left no mark";
}

TEST_F(RecognitionReportTest, BrokenReportsNameTheField) {
  json bad = report_;
  bad["objects"][0]["segment"][3] = 500;
  EXPECT_NE(ErrorOf(bad).find("objects[0].segment[3]"), std::string::npos) << ErrorOf(bad);
  bad = report_;
  bad["objects"][0]["T_S_O"]["matrix"][0][0] = 2.0;
  EXPECT_NE(ErrorOf(bad).find("not a rigid motion"), std::string::npos) << ErrorOf(bad);
  bad = report_;
  bad["scan_points"] = 999;
  EXPECT_NE(ErrorOf(bad).find("was it changed"), std::string::npos) << ErrorOf(bad);
  bad = report_;
  bad["objects"][0]["id"] = "hammer";
  EXPECT_NE(ErrorOf(bad).find("has no object 'hammer'"), std::string::npos) << ErrorOf(bad);
  bad = report_;
  bad["uwscan_format"] = 2;
  EXPECT_NE(ErrorOf(bad).find("uwscan_format"), std::string::npos) << ErrorOf(bad);
  bad = report_;
  bad["database"] = "missing.db";
  EXPECT_NE(ErrorOf(bad).find("missing.db"), std::string::npos) << ErrorOf(bad);
}

}  // namespace
}  // namespace uwscan::viewer
