#include "scanner/calibration/calibration_dataset.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>

#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::scanner::calibration {
namespace {

namespace fs = std::filesystem;

// This process's scratch folder, removed when the test program ends.
fs::path ScratchRoot() {
  return fs::temp_directory_path() / ("uwscan_dataset_test_" + std::to_string(getpid()));
}
struct RemoveScratch : ::testing::Environment {
  void TearDown() override { fs::remove_all(ScratchRoot()); }
};
[[maybe_unused]] const ::testing::Environment* const kRemoveScratch =
    ::testing::AddGlobalTestEnvironment(new RemoveScratch);

// A fresh empty folder per test.
fs::path TestFolder(const std::string& name) {
  fs::path folder = ScratchRoot() / name;
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

void WritePng(const fs::path& path, int width = 32, int height = 24, int type = CV_8UC1) {
  ASSERT_TRUE(cv::imwrite(path.string(), cv::Mat(height, width, type, cv::Scalar::all(7))));
}

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

std::string LoadError(const fs::path& folder) {
  try {
    LoadCalibrationDataset(folder);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

// A laser dataset of two planes with two stripes each, images in place, plus scanner and truth.
CalibrationDataset LaserDataset(const fs::path& folder) {
  CalibrationDataset d;
  d.folder = folder;
  d.step = "laser";
  d.pattern.type = PatternType::kCharuco;
  d.pattern.columns = 8;
  d.pattern.rows = 6;
  d.pattern.square_m = 0.04;
  d.pattern.marker_m = 0.03;
  d.width_px = 32;
  d.height_px = 24;
  for (int p = 0; p < 2; ++p) {
    CalibrationDataset::Plane plane;
    plane.pattern_image = "plane_" + std::to_string(p) + ".png";
    WritePng(folder / plane.pattern_image);
    for (const int step : {-100, 20}) {
      const std::string image =
          "plane_" + std::to_string(p) + "_step_" + std::to_string(step) + ".png";
      WritePng(folder / image);
      plane.stripes.emplace_back(image, step);
    }
    d.planes.push_back(plane);
  }
  WriteText(folder / "initial_scanner.yaml", "uwscan_format: 1\n");
  d.scanner_file = folder / "initial_scanner.yaml";
  WriteText(folder / "truth.yaml", "uwscan_format: 1\n");
  d.truth_file = folder / "truth.yaml";
  return d;
}

TEST(CalibrationDataset, ManifestRoundTrips) {
  const fs::path folder = TestFolder("round_trip");
  const CalibrationDataset written = LaserDataset(folder);
  WriteCalibrationManifest(written);
  const CalibrationDataset read = LoadCalibrationDataset(folder);
  EXPECT_EQ(read.step, "laser");
  EXPECT_EQ(read.pattern.type, PatternType::kCharuco);
  EXPECT_EQ(read.pattern.columns, 8);
  EXPECT_EQ(read.pattern.square_m, 0.04);
  EXPECT_EQ(read.pattern.marker_m, 0.03);
  EXPECT_EQ(read.pattern.dictionary, "DICT_4X4_50");
  EXPECT_EQ(read.width_px, 32);
  ASSERT_EQ(read.planes.size(), 2u);
  EXPECT_EQ(read.planes[1].pattern_image, "plane_1.png");
  EXPECT_EQ(read.planes[1].stripes, written.planes[1].stripes);
  ASSERT_TRUE(read.scanner_file && read.truth_file);
  EXPECT_TRUE(fs::equivalent(*read.scanner_file, folder / "initial_scanner.yaml"));
  EXPECT_EQ(read.ImagePath("plane_0.png"), folder / "plane_0.png");
  // Paths inside the folder are written relative to it: the folder can move.
  std::ifstream manifest(folder / kManifestFileName);
  const std::string text((std::istreambuf_iterator<char>(manifest)), {});
  EXPECT_NE(text.find("scanner: initial_scanner.yaml"), std::string::npos) << text;
  EXPECT_NE(text.find("{type: charuco, columns: 8, rows: 6, square_m: 0.04"), std::string::npos)
      << text;
  // Written by rename: no temporary file stays behind.
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos);
  }
}

TEST(CalibrationDataset, MemsDotsKeepTheirVoltsExactly) {
  const fs::path folder = TestFolder("mems");
  CalibrationDataset d;
  d.folder = folder;
  d.step = "mems";
  d.width_px = 32;
  d.height_px = 24;
  const Eigen::Vector2d volts[2] = {{-9.0, 9.0}, {0.1 + 0.2, -1.0 / 3.0}};
  for (int p = 0; p < 2; ++p) {
    CalibrationDataset::Plane plane;
    plane.pattern_image = "plane_" + std::to_string(p) + ".png";
    WritePng(folder / plane.pattern_image, 32, 24, CV_16UC1);
    for (int k = 0; k < 2; ++k) {
      const std::string image = "dot_" + std::to_string(p) + "_" + std::to_string(k) + ".png";
      WritePng(folder / image, 32, 24, CV_16UC1);
      plane.dots.emplace_back(image, volts[k]);
    }
    d.planes.push_back(plane);
  }
  WriteCalibrationManifest(d);
  const CalibrationDataset read = LoadCalibrationDataset(folder);
  ASSERT_EQ(read.planes.size(), 2u);
  EXPECT_FALSE(read.scanner_file.has_value());
  EXPECT_EQ(read.planes[1].dots[1].second, volts[1]);  // bit for bit
  EXPECT_EQ(read.planes[0].dots[0].first, "dot_0_0.png");
}

TEST(CalibrationDataset, TruthRoundTripsToTheSameDoubles) {
  const fs::path folder = TestFolder("truth");
  DatasetTruth truth;
  truth.scanner = DefaultScanner(ScannerKind::kMems);
  truth.scanner.camera().camera.fx_px = 1750.0 + 1.0 / 3.0;
  for (int i = 0; i < 3; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() =
        Eigen::AngleAxisd(0.3 + i, Eigen::Vector3d(1, 2, 3 - i).normalized()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(0.1 / 3.0, -0.7 * i, 1.0 + 1e-9 * i);
    truth.T_C_O_views.push_back(T);
  }
  truth.T_C_O_planes.push_back(truth.T_C_O_views[1]);
  WriteDatasetTruth(folder / "truth.yaml", truth);
  const DatasetTruth read = LoadDatasetTruth(folder / "truth.yaml");
  EXPECT_EQ(ScannerToYaml(read.scanner), ScannerToYaml(truth.scanner));
  ASSERT_EQ(read.T_C_O_views.size(), 3u);
  ASSERT_EQ(read.T_C_O_planes.size(), 1u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(read.T_C_O_views[i].translation(), truth.T_C_O_views[i].translation());
    EXPECT_LT((read.T_C_O_views[i].linear() - truth.T_C_O_views[i].linear()).norm(), 1e-15);
  }
  EXPECT_THROW(LoadDatasetTruth(folder / "missing.yaml"), Error);
}

// Writes a manifest (a laser dataset of 32 x 24 images unless the text says otherwise) with the
// images it names, then one change applied to the text.
class BrokenManifest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = TestFolder(::testing::UnitTest::GetInstance()->current_test_info()->name());
    for (const char* image :
         {"p0.png", "p0_a.png", "p0_b.png", "p1.png", "p1_a.png", "v0.png", "v1.png", "v2.png"}) {
      WritePng(folder_ / image);
    }
  }
  std::string Load(const std::string& manifest) {
    WriteText(folder_ / kManifestFileName, manifest);
    return LoadError(folder_);
  }
  static std::string Laser(
      const std::string& plane1_stripes = "[{image: p1_a.png, mirror_step: 10}]") {
    return "uwscan_format: 1\n"                                                  // 1
           "dataset: calibration\n"                                              // 2
           "step: laser\n"                                                       // 3
           "pattern: {type: chessboard, columns: 9, rows: 6, square_m: 0.03}\n"  // 4
           "image_size: [32, 24]\n"                                              // 5
           "planes:\n"                                                           // 6
           "  - pattern_image: p0.png\n"                                         // 7
           "    stripes:\n"                                                      // 8
           "      - {image: p0_a.png, mirror_step: -10}\n"                       // 9
           "      - {image: p0_b.png, mirror_step: 30}\n"                        // 10
           "  - pattern_image: p1.png\n"                                         // 11
           "    stripes: " +
           plane1_stripes + "\n";  // 12
  }
  fs::path folder_;
};

TEST_F(BrokenManifest, TheValidOneLoads) { EXPECT_EQ(Load(Laser()), "(no error)"); }

TEST_F(BrokenManifest, MissingFolderOrManifest) {
  const std::string no_folder = LoadError(folder_ / "nowhere");
  EXPECT_NE(no_folder.find("nowhere: no such calibration dataset folder"), std::string::npos)
      << no_folder;
  const std::string no_manifest = LoadError(folder_);
  EXPECT_NE(no_manifest.find("manifest.yaml: missing"), std::string::npos) << no_manifest;
  const std::string file = LoadError(folder_ / "p0.png");
  EXPECT_NE(file.find("not a folder"), std::string::npos) << file;
}

TEST_F(BrokenManifest, MalformedYamlNamesTheLine) {
  std::string text = Laser();
  text.replace(text.find("image_size: [32, 24]"), 20, "image_size: [32, 24");
  const std::string error = Load(text);
  EXPECT_NE(error.find("manifest.yaml:"), std::string::npos) << error;
  EXPECT_NE(error.find("not valid YAML"), std::string::npos) << error;
}

TEST_F(BrokenManifest, UnknownStepOrField) {
  std::string text = Laser();
  text.replace(text.find("step: laser"), 11, "step: lasers");
  std::string error = Load(text);
  EXPECT_NE(error.find("manifest.yaml:3: field 'step': got 'lasers', expected one of"),
            std::string::npos)
      << error;
  error = Load(Laser() + "truths: truth.yaml\n");
  EXPECT_NE(error.find("manifest.yaml:13: field 'truths': unknown field"), std::string::npos)
      << error;
  error = Load(Laser("[{image: p1_a.png, mirror_stp: 10}]"));
  EXPECT_NE(error.find("field 'planes[1].stripes[0].mirror_stp': unknown field"), std::string::npos)
      << error;
  text = Laser();
  text.replace(text.find("dataset: calibration"), 20, "dataset: dive");
  error = Load(text);
  EXPECT_NE(error.find("field 'dataset': got 'dive', expected calibration"), std::string::npos)
      << error;
}

TEST_F(BrokenManifest, MissingImageIsNamed) {
  const std::string error = Load(Laser("[{image: p1_c.png, mirror_step: 10}]"));
  EXPECT_NE(error.find("manifest.yaml:12: field 'planes[1].stripes[0].image': image 'p1_c.png' "
                       "not found"),
            std::string::npos)
      << error;
}

TEST_F(BrokenManifest, StepWithoutItsData) {
  std::string error = Load(Laser("[]"));
  EXPECT_NE(error.find("field 'planes[1]': a laser dataset needs stripes on every plane"),
            std::string::npos)
      << error;
  std::string one_step = Laser("[{image: p1_a.png, mirror_step: -10}]");
  const std::string second = "      - {image: p0_b.png, mirror_step: 30}\n";
  one_step.erase(one_step.find(second), second.size());
  error = Load(one_step);
  EXPECT_NE(error.find("at least 2 distinct mirror steps"), std::string::npos) << error;
  const std::string intrinsics =
      "uwscan_format: 1\ndataset: calibration\nstep: intrinsics\n"
      "pattern: {type: chessboard, columns: 9, rows: 6, square_m: 0.03}\n"
      "image_size: [32, 24]\n"
      "views: [{image: v0.png}, {image: v1.png}]\n";
  error = Load(intrinsics);
  EXPECT_NE(error.find("manifest.yaml:6: field 'views': a intrinsics dataset needs at least 3 "
                       "views of the pattern, got 2"),
            std::string::npos)
      << error;
  std::string three = intrinsics;
  three.replace(three.find("{image: v1.png}"), 15, "{image: v1.png}, {image: v2.png}");
  error = Load(three +
               "planes: [{pattern_image: p0.png, stripes: [{image: p0_a.png, "
               "mirror_step: 1}]}]\n");
  EXPECT_NE(error.find("planes are for laser and mems"), std::string::npos) << error;
}

TEST_F(BrokenManifest, InconsistentManifest) {
  // The same image twice.
  std::string error = Load(Laser("[{image: p0_a.png, mirror_step: 10}]"));
  EXPECT_NE(error.find("field 'planes[1].stripes[0].image': image 'p0_a.png' is also "
                       "planes[0].stripes[0].image"),
            std::string::npos)
      << error;
  // A mirror step twice on one plane.
  error = Load(Laser("[{image: p1_a.png, mirror_step: 10}, {image: p0_b.png, mirror_step: 10}]"));
  EXPECT_NE(error.find("manifest.yaml:12: field 'planes[1].stripes[1].mirror_step': mirror step "
                       "10 appears twice"),
            std::string::npos)
      << error;
  // Dots in a laser dataset; volts that are not numbers.
  std::string text = Laser() + "    dots: [{image: v0.png, volts: [1, 2]}]\n";
  error = Load(text);
  EXPECT_NE(error.find("field 'planes[1].dots': dots belong to mems datasets"), std::string::npos)
      << error;
  text.replace(text.find("step: laser"), 11, "step: mems");
  text.replace(text.find("volts: [1, 2]"), 13, "volts: [.nan, 2]");
  error = Load(text);
  EXPECT_NE(error.find("manifest.yaml:13: field 'planes[1].dots[0].volts[0]': expected a finite "
                       "number"),
            std::string::npos)
      << error;
}

TEST_F(BrokenManifest, ImagesOfTheWrongKind) {
  WritePng(folder_ / "big.png", 64, 24);
  std::string error = Load(Laser("[{image: big.png, mirror_step: 10}]"));
  EXPECT_NE(error.find("image 'big.png' is 64x24 px, the manifest's image_size is [32, 24]"),
            std::string::npos)
      << error;
  WritePng(folder_ / "colour.png", 32, 24, CV_8UC3);
  error = Load(Laser("[{image: colour.png, mirror_step: 10}]"));
  EXPECT_NE(error.find("image 'colour.png' is not 8- or 16-bit greyscale"), std::string::npos)
      << error;
  WriteText(folder_ / "text.png", "not an image at all, just text");
  error = Load(Laser("[{image: text.png, mirror_step: 10}]"));
  EXPECT_NE(error.find("image 'text.png' is not a PNG file"), std::string::npos) << error;
  error = Load(Laser("[{image: ../p1_a.png, mirror_step: 10}]"));
  EXPECT_NE(error.find("expected a file name inside the dataset folder"), std::string::npos)
      << error;
}

TEST_F(BrokenManifest, MissingScannerOrTruthFile) {
  std::string error = Load(Laser() + "scanner: cad.yaml\n");
  EXPECT_NE(error.find("manifest.yaml:13: field 'scanner': scanner file not found"),
            std::string::npos)
      << error;
  error = Load(Laser() + "truth: truth.yaml\n");
  EXPECT_NE(error.find("field 'truth': truth file not found"), std::string::npos) << error;
}

TEST(CalibrationDataset, WriterChecksLikeTheReader) {
  const fs::path folder = TestFolder("writer_checks");
  CalibrationDataset d = LaserDataset(folder);
  d.planes[1].dots.emplace_back("plane_0.png",
                                Eigen::Vector2d(std::numeric_limits<double>::infinity(), 0.0));
  try {
    WriteCalibrationManifest(d);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("(being written): field 'planes[1].dots'"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(folder / kManifestFileName));
  d = LaserDataset(folder);
  d.step = "mems";
  d.planes.clear();
  EXPECT_THROW(WriteCalibrationManifest(d), Error);
}

}  // namespace
}  // namespace uwscan::scanner::calibration
