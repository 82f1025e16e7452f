#include "scanner/calibration/opencv_camera_import.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::calibration {
namespace {

// A fresh directory per test, removed at the end.
class ImportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("uwscan_import_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // Writes what OpenCV's calibration sample writes (the nodes this import reads, and some it
  // ignores), with `distortion` as a column vector, the sample's layout.
  std::filesystem::path Write(const std::string& name, const std::vector<double>& distortion,
                              double skew = 0.0, bool with_matrix = true) const {
    const std::filesystem::path path = dir_ / name;
    cv::FileStorage storage(path.string(), cv::FileStorage::WRITE);
    storage << "calibration_time"
            << "Thu 01 Jan 1970 00:00:00 UTC";
    storage << "nr_of_frames" << 20;
    storage << "image_width" << 2048;
    storage << "image_height" << 1088;
    storage << "flags" << 0;
    if (with_matrix) {
      const cv::Mat K =
          (cv::Mat_<double>(3, 3) << 1751.25, skew, 1022.75, 0.0, 1749.5, 545.125, 0.0, 0.0, 1.0);
      storage << "camera_matrix" << K;
    }
    storage << "distortion_coefficients" << cv::Mat(distortion, true);
    storage << "avg_reprojection_error" << 0.21;
    storage.release();
    return path;
  }

  std::filesystem::path dir_;
};

void ExpectErrorMentions(const std::filesystem::path& path, const std::vector<std::string>& parts) {
  try {
    ImportOpenCvCalibration(path);
    ADD_FAILURE() << path << " accepted";
  } catch (const Error& e) {
    for (const std::string& part : parts) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos)
          << "'" << e.what() << "' does not mention '" << part << "'";
    }
  }
}

TEST_F(ImportTest, RoundTripFiveCoefficients) {
  const std::filesystem::path path = Write("camera.yaml", {-0.12, 0.08, 0.0005, -0.0003, -0.02});
  const PinholeCamera camera = ImportOpenCvCalibration(path);
  EXPECT_EQ(camera.width_px, 2048);
  EXPECT_EQ(camera.height_px, 1088);
  EXPECT_EQ(camera.fx_px, 1751.25);
  EXPECT_EQ(camera.fy_px, 1749.5);
  EXPECT_EQ(camera.cx_px, 1022.75);
  EXPECT_EQ(camera.cy_px, 545.125);
  EXPECT_EQ(camera.k1, -0.12);
  EXPECT_EQ(camera.k2, 0.08);
  EXPECT_EQ(camera.p1, 0.0005);
  EXPECT_EQ(camera.p2, -0.0003);
  EXPECT_EQ(camera.k3, -0.02);
}

TEST_F(ImportTest, FourAndEightCoefficientsAndXml) {
  const PinholeCamera four =
      ImportOpenCvCalibration(Write("four.yaml", {-0.1, 0.05, 0.001, 0.002}));
  EXPECT_EQ(four.k1, -0.1);
  EXPECT_EQ(four.p2, 0.002);
  EXPECT_EQ(four.k3, 0.0);
  // Eight values with the rational terms zero: the standard model written in the long form.
  const PinholeCamera eight =
      ImportOpenCvCalibration(Write("eight.yaml", {-0.1, 0.05, 0.001, 0.002, 0.01, 0.0, 0.0, 0.0}));
  EXPECT_EQ(eight.k3, 0.01);
  const PinholeCamera xml =
      ImportOpenCvCalibration(Write("camera.xml", {-0.1, 0.05, 0.0, 0.0, 0.01}));
  EXPECT_EQ(xml.k1, -0.1);
  EXPECT_EQ(xml.fx_px, 1751.25);
}

TEST_F(ImportTest, RefusesUnsupportedModels) {
  ExpectErrorMentions(Write("rational.yaml", {-0.1, 0.05, 0.0, 0.0, 0.01, 0.3, 0.0, 0.0}),
                      {"rational.yaml", "k4", "non-zero"});
  std::vector<double> prism(12, 0.0);
  prism[9] = 1e-4;  // s2
  ExpectErrorMentions(Write("prism.yaml", prism), {"prism.yaml", "s2"});
  std::vector<double> tilted(14, 0.0);
  tilted[13] = 0.01;
  ExpectErrorMentions(Write("tilted.yaml", tilted), {"tilted.yaml", "tau_y"});
  ExpectErrorMentions(Write("six.yaml", {0, 0, 0, 0, 0, 0}),
                      {"six.yaml", "distortion_coefficients", "4, 5, 8, 12 or 14"});
  ExpectErrorMentions(Write("skew.yaml", {0, 0, 0, 0, 0}, 0.5), {"skew.yaml", "skew"});
}

TEST_F(ImportTest, MalformedFilesNameTheFileAndTheNode) {
  ExpectErrorMentions(Write("no_matrix.yaml", {0, 0, 0, 0, 0}, 0.0, false),
                      {"no_matrix.yaml", "missing node 'camera_matrix'"});
  ExpectErrorMentions(dir_ / "absent.yaml", {"absent.yaml", "no such file"});

  const std::filesystem::path garbage = dir_ / "garbage.yaml";
  std::ofstream(garbage) << "%YAML:1.0\n---\nimage_width: [1, 2\n  camera_matrix: {{{\n";
  ExpectErrorMentions(garbage, {"garbage.yaml"});

  const std::filesystem::path text = dir_ / "text.yaml";
  std::ofstream(text) << "%YAML:1.0\n---\nimage_width: wide\nimage_height: 1088\n";
  ExpectErrorMentions(text, {"text.yaml", "'image_width' must be an integer"});

  const std::filesystem::path scalar = dir_ / "scalar.yaml";
  std::ofstream(scalar) << "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n"
                           "camera_matrix: 3.0\n";
  ExpectErrorMentions(scalar, {"scalar.yaml", "'camera_matrix' must be an OpenCV matrix"});

  const std::filesystem::path no_height = dir_ / "no_height.yaml";
  std::ofstream(no_height) << "%YAML:1.0\n---\nimage_width: 640\n";
  ExpectErrorMentions(no_height, {"no_height.yaml", "missing node 'image_height'"});

  const std::filesystem::path bad_focal = dir_ / "bad_focal.yaml";
  {
    cv::FileStorage storage(bad_focal.string(), cv::FileStorage::WRITE);
    storage << "image_width" << 640 << "image_height" << 480;
    storage << "camera_matrix" << (cv::Mat_<double>(3, 3) << 0, 0, 320, 0, 500, 240, 0, 0, 1);
    storage << "distortion_coefficients" << cv::Mat(std::vector<double>(5, 0.0), true);
  }
  ExpectErrorMentions(bad_focal, {"bad_focal.yaml", "fx_px"});
}

TEST_F(ImportTest, HandWrittenXmlAndFlowYamlAreRead) {
  // What other tools write in OpenCV's layouts: XML with the data over several lines, and YAML
  // with "1." numbers and the matrix as a flow map.
  const std::filesystem::path xml = dir_ / "hand.xml";
  std::ofstream(xml)
      << "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>640</image_width>"
         "<image_height> 480 </image_height>\n<camera_matrix type_id=\"opencv-matrix\">"
         "<rows>3</rows><cols>3</cols><dt>d</dt>\n<data>\n  500. 0. 320.\n  0. 501. 240."
         "\n  0. 0. 1.</data></camera_matrix>\n<distortion_coefficients "
         "type_id=\"opencv-matrix\"><rows>1</rows><cols>4</cols><dt>f</dt><data>"
         "0.1 -0.2 0 0</data></distortion_coefficients>\n</opencv_storage>\n";
  const PinholeCamera from_xml = ImportOpenCvCalibration(xml);
  EXPECT_EQ(from_xml.height_px, 480);
  EXPECT_EQ(from_xml.fy_px, 501.0);
  EXPECT_EQ(from_xml.k2, -0.2);

  const std::filesystem::path yaml = dir_ / "flow.yaml";
  std::ofstream(yaml)
      << "%YAML:1.0\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix "
         "{rows: 3, cols: 3, dt: d, data: [500., 0., 320., 0., 501., 240., 0., 0., 1.]}\n"
         "distortion_coefficients: !!opencv-matrix\n  rows: 4\n  cols: 1\n  dt: d\n"
         "  data: [ 0.1, -0.2, 0., 0. ]\n";
  const PinholeCamera from_yaml = ImportOpenCvCalibration(yaml);
  EXPECT_EQ(from_yaml.cx_px, 320.0);
  EXPECT_EQ(from_yaml.k1, 0.1);
}

// OpenCV's calibration sample also writes per-view nodes (here for 20 views: larger than any
// matrix the import reads, and of two channels): they are not read, so they do not matter.
TEST_F(ImportTest, PerViewNodesOfTheSampleAreIgnored) {
  for (const char* name : {"views.yaml", "views.xml"}) {
    const std::filesystem::path path = dir_ / name;
    {
      cv::FileStorage storage(path.string(), cv::FileStorage::WRITE);
      storage << "image_width" << 2048 << "image_height" << 1088;
      storage << "camera_matrix"
              << (cv::Mat_<double>(3, 3) << 1751.25, 0.0, 1022.75, 0.0, 1749.5, 545.125, 0.0, 0.0,
                  1.0);
      storage << "distortion_coefficients"
              << cv::Mat(std::vector<double>{-0.12, 0.08, 0.0, 0.0, -0.02}, true);
      storage << "extrinsic_parameters" << cv::Mat(20, 6, CV_64F, cv::Scalar(0.5));
      storage << "image_points" << cv::Mat(20, 54, CV_32FC2, cv::Scalar(100.0f, 200.0f));
    }
    const PinholeCamera camera = ImportOpenCvCalibration(path);
    EXPECT_EQ(camera.fx_px, 1751.25) << name;
    EXPECT_EQ(camera.k3, -0.02) << name;
  }
}

// Damaged files that hung, crashed or exhausted memory in OpenCV's FileStorage, and others of
// their kind: each is refused with one error naming the file and what is wrong.
TEST_F(ImportTest, DamagedFilesAreRefused) {
  const auto write = [this](const std::string& name, const std::string& text) {
    const std::filesystem::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
  };
  // The input that hung FileStorage (tests/fuzz/regressions/opencv_intrinsics/timeout-*).
  ExpectErrorMentions(
      write("hang.yaml", "%YAML:1.x:i! !opencv-matrix\n   row7ro 13 :*:0\n%Y--\nima:"),
      {"hang.yaml", "malformed YAML"});
  ExpectErrorMentions(write("deep.yaml", "image_width: " + std::string(100000, '[')),
                      {"deep.yaml", "malformed YAML"});
  std::string nested = "<opencv_storage>";
  for (int i = 0; i < 1000; ++i) nested += "<a>";
  for (int i = 0; i < 1000; ++i) nested += "</a>";
  ExpectErrorMentions(write("nested.xml", nested + "</opencv_storage>"),
                      {"nested.xml", "malformed XML", "depth"});
  ExpectErrorMentions(
      write("entities.xml",
            "<?xml version=\"1.0\"?><!DOCTYPE a [<!ENTITY a \"aaaaaaaaaa\"><!ENTITY b "
            "\"&a;&a;&a;&a;&a;&a;&a;&a;\">]><opencv_storage><image_width>&b;</image_width>"
            "</opencv_storage>"),
      {"entities.xml", "'image_width' must be an integer"});
  ExpectErrorMentions(
      write("root.xml", "<calibration><image_width>640</image_width></calibration>"),
      {"root.xml", "<opencv_storage>"});
  ExpectErrorMentions(write("huge_rows.yaml",
                            "image_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n"
                            "  rows: 2000000000\n  cols: 3\n  dt: d\n  data: [1, 2, 3]\n"),
                      {"huge_rows.yaml", "'camera_matrix'", "rows and cols"});
  ExpectErrorMentions(write("short.yaml",
                            "image_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n"
                            "  rows: 3\n  cols: 3\n  dt: d\n  data: [1, 2, 3]\n"),
                      {"short.yaml", "data has 3 values, rows x cols = 9"});
  ExpectErrorMentions(write("nan.yaml",
                            "image_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n"
                            "  rows: 1\n  cols: 3\n  dt: d\n  data: [1, .nan, 3]\n"),
                      {"nan.yaml", "not a finite number"});
  ExpectErrorMentions(
      write("short.xml",
            "<opencv_storage><image_width>640</image_width><image_height>480"
            "</image_height><camera_matrix type_id=\"opencv-matrix\"><rows>3</rows>"
            "<cols>3</cols><dt>d</dt><data>1 2 3</data></camera_matrix></opencv_storage>"),
      {"short.xml", "data has 3 values"});
  ExpectErrorMentions(write("binary.yaml", std::string("image_width: 6\x80\x00\n", 16)),
                      {"binary.yaml", "not ASCII text"});
  ExpectErrorMentions(write("list.yaml", "- 1\n- 2\n"), {"list.yaml", "not a map"});
  ExpectErrorMentions(write("big.yaml", std::string((1 << 20) + 1, ' ')),
                      {"big.yaml", "larger than 1 MiB"});
}

}  // namespace
}  // namespace uwscan::scanner::calibration
