#include "scanner/calibration/pattern_detection.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::calibration {
namespace {

constexpr int kWidth = 1024;
constexpr int kHeight = 768;
constexpr int kSuper = 4;  // supersampling per axis: area-sampled edges, like a sensor

// The homography from the pattern plane (x_O, y_O in metres) to pixels of a pinhole camera
// (no distortion) looking at the pattern posed by T_C_O.
Eigen::Matrix3d PlaneToImage(const Eigen::Isometry3d& T_C_O) {
  Eigen::Matrix3d K;
  K << 900.0, 0.0, 511.5, 0.0, 900.0, 383.5, 0.0, 0.0, 1.0;
  Eigen::Matrix3d Rt;
  Rt << T_C_O.linear().col(0), T_C_O.linear().col(1), T_C_O.translation();
  return K * Rt;
}

Eigen::Vector2d Apply(const Eigen::Matrix3d& H, const Eigen::Vector3d& p_O) {
  const Eigen::Vector3d q = H * Eigen::Vector3d(p_O.x(), p_O.y(), 1.0);
  return q.head<2>() / q.z();
}

// Pose of a pattern of size w x h metres (origin at its corner) centred `depth` ahead,
// tilted about x and y and spun about its normal.
Eigen::Isometry3d Pose(double w, double h, double depth, double tilt_x, double tilt_y, double spin,
                       const Eigen::Vector2d& shift = Eigen::Vector2d::Zero()) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(tilt_x, Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(tilt_y, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(spin, Eigen::Vector3d::UnitZ()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(shift.x(), shift.y(), depth) -
                    T.linear() * Eigen::Vector3d(w / 2, h / 2, 0.0);
  return T;
}

// Renders a planar pattern given by its reflectance (0 black .. 1 white) as a function of
// (x_O, y_O), with kSuper x kSuper samples per pixel; white paper outside the pattern.
cv::Mat Render(const Eigen::Matrix3d& H, const std::function<double(double, double)>& shade) {
  const Eigen::Matrix3d H_inverse = H.inverse();
  cv::Mat image(kHeight, kWidth, CV_8U);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      double sum = 0.0;
      for (int j = 0; j < kSuper; ++j) {
        for (int i = 0; i < kSuper; ++i) {
          // Pixel centres at integers (OpenCV): pixel u spans [u - 0.5, u + 0.5).
          const Eigen::Vector3d q = H_inverse * Eigen::Vector3d(u - 0.5 + (i + 0.5) / kSuper,
                                                                v - 0.5 + (j + 0.5) / kSuper, 1.0);
          sum += shade(q.x() / q.z(), q.y() / q.z());
        }
      }
      image.at<std::uint8_t>(v, u) =
          cv::saturate_cast<std::uint8_t>(20.0 + 215.0 * sum / (kSuper * kSuper));
    }
  }
  return image;
}

// A chessboard with spec.columns x spec.rows inner corners, the first at the origin; black
// squares where (ix + iy) is even, ix = floor(x / s) counting from the first square at -1.
std::function<double(double, double)> ChessboardShade(const PatternSpec& spec) {
  return [spec](double x, double y) {
    const double s = spec.square_m;
    if (x < -s || y < -s || x >= spec.columns * s || y >= spec.rows * s) return 1.0;
    const long ix = static_cast<long>(std::floor(x / s));
    const long iy = static_cast<long>(std::floor(y / s));
    return ((ix + iy) % 2 == 0) ? 0.0 : 1.0;
  };
}

// The ChArUco board as OpenCV 4.6 draws it, sampled at 100 px per square.
std::function<double(double, double)> CharucoShade(const PatternSpec& spec) {
  constexpr int kPixelsPerSquare = 100;
  const cv::Ptr<cv::aruco::CharucoBoard> board = cv::aruco::CharucoBoard::create(
      spec.columns, spec.rows, static_cast<float>(spec.square_m), static_cast<float>(spec.marker_m),
      cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50));
  cv::Mat drawing;
  board->draw(cv::Size(spec.columns * kPixelsPerSquare, spec.rows * kPixelsPerSquare), drawing, 0,
              1);
  return [drawing, spec](double x, double y) {
    const double scale = kPixelsPerSquare / spec.square_m;
    const int bx = static_cast<int>(std::floor(x * scale));
    const int by = static_cast<int>(std::floor(y * scale));
    if (bx < 0 || by < 0 || bx >= drawing.cols || by >= drawing.rows) return 1.0;
    return drawing.at<std::uint8_t>(by, bx) / 255.0;
  };
}

class DetectPatternTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("uwscan_detect_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path Save(const std::string& name, const cv::Mat& image) const {
    const std::filesystem::path path = dir_ / name;
    EXPECT_TRUE(cv::imwrite(path.string(), image));
    return path;
  }

  std::filesystem::path dir_;
};

// Largest distance of the detected corners from where the homography puts CornerPoints_O.
double WorstCornerError(const PatternObservation& observation, const PatternSpec& spec,
                        const Eigen::Matrix3d& H) {
  const std::vector<Eigen::Vector3d> points_O = spec.CornerPoints_O();
  double worst = 0.0;
  for (std::size_t k = 0; k < observation.corner_ids.size(); ++k) {
    const Eigen::Vector2d expected =
        Apply(H, points_O[static_cast<std::size_t>(observation.corner_ids[k])]);
    worst = std::max(worst, (observation.corners_px[k] - expected).norm());
  }
  return worst;
}

PatternSpec Chessboard() {
  PatternSpec spec;
  spec.columns = 9;
  spec.rows = 6;
  spec.square_m = 0.03;
  return spec;
}

PatternSpec Charuco() {
  PatternSpec spec;
  spec.type = PatternType::kCharuco;
  spec.columns = 7;
  spec.rows = 5;
  spec.square_m = 0.04;
  spec.marker_m = 0.03;
  spec.dictionary = "DICT_4X4_50";
  return spec;
}

// Views of the chessboard, including ones turned by 90 and 180 degrees: a 9 x 6 board has one
// odd and one even count, so its ids must follow the board, not the image.
TEST_F(DetectPatternTest, ChessboardCornersMatchTheHomography) {
  const PatternSpec spec = Chessboard();
  const double w = (spec.columns - 1) * spec.square_m;
  const double h = (spec.rows - 1) * spec.square_m;
  const std::vector<Eigen::Isometry3d> poses = {
      Pose(w, h, 0.6, 0.0, 0.0, 0.0),
      Pose(w, h, 0.7, 0.4, -0.3, 0.3, Eigen::Vector2d(0.05, 0.02)),
      Pose(w, h, 0.6, -0.5, 0.2, 0.5 * std::numbers::pi),
      Pose(w, h, 0.65, 0.3, 0.45, std::numbers::pi),
      Pose(w, h, 0.9, -0.2, -0.6, -2.0, Eigen::Vector2d(-0.1, 0.05)),
  };
  double worst_all = 0.0;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const Eigen::Matrix3d H = PlaneToImage(poses[k]);
    cv::Mat image = Render(H, ChessboardShade(spec));
    cv::GaussianBlur(image, image, cv::Size(0, 0), 0.7);  // optics
    const std::filesystem::path path = Save("chess" + std::to_string(k) + ".png", image);
    const std::optional<PatternObservation> observation = DetectPattern(path, spec);
    ASSERT_TRUE(observation) << k;
    EXPECT_EQ(observation->image, path.string());
    ASSERT_EQ(observation->corner_ids.size(), 54u);
    const double worst = WorstCornerError(*observation, spec, H);
    EXPECT_LT(worst, 0.1) << "view " << k;
    worst_all = std::max(worst_all, worst);
  }
  std::printf("[chessboard] worst corner error over %zu views: %.4f px\n", poses.size(), worst_all);
}

TEST_F(DetectPatternTest, ChessboardWithNoiseColourAndMono16) {
  const PatternSpec spec = Chessboard();
  const Eigen::Matrix3d H = PlaneToImage(Pose((spec.columns - 1) * spec.square_m,
                                              (spec.rows - 1) * spec.square_m, 0.7, 0.3, 0.2, 0.2));
  cv::Mat image = Render(H, ChessboardShade(spec));
  cv::GaussianBlur(image, image, cv::Size(0, 0), 0.7);

  // 12-bit data in a 16-bit PNG (Mono16 cameras), with sensor noise of ~1 % of the range.
  cv::Mat mono16;
  image.convertTo(mono16, CV_16U, 16.0);
  cv::Mat noise(mono16.size(), CV_16S);
  cv::RNG rng(5);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 40.0);
  cv::Mat noisy;
  cv::add(mono16, noise, noisy, cv::noArray(), CV_16U);
  const std::optional<PatternObservation> from16 = DetectPattern(Save("mono16.png", noisy), spec);
  ASSERT_TRUE(from16);
  const double worst16 = WorstCornerError(*from16, spec, H);
  EXPECT_LT(worst16, 0.1);

  cv::Mat colour;
  cv::cvtColor(image, colour, cv::COLOR_GRAY2BGR);
  const std::optional<PatternObservation> from_colour =
      DetectPattern(Save("colour.png", colour), spec);
  ASSERT_TRUE(from_colour);
  EXPECT_LT(WorstCornerError(*from_colour, spec, H), 0.1);
  std::printf("[chessboard] Mono16 with noise: worst corner error %.4f px\n", worst16);
}

TEST_F(DetectPatternTest, CharucoCornersMatchTheHomography) {
  const PatternSpec spec = Charuco();
  const double w = spec.columns * spec.square_m;
  const double h = spec.rows * spec.square_m;
  const std::vector<Eigen::Isometry3d> poses = {
      Pose(w, h, 0.6, 0.0, 0.0, 0.0),
      Pose(w, h, 0.7, 0.4, -0.3, 0.3),
      Pose(w, h, 0.65, -0.3, 0.4, std::numbers::pi),
      Pose(w, h, 0.8, 0.2, 0.5, -1.2, Eigen::Vector2d(0.05, -0.03)),
  };
  double worst_all = 0.0;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const Eigen::Matrix3d H = PlaneToImage(poses[k]);
    cv::Mat image = Render(H, CharucoShade(spec));
    cv::GaussianBlur(image, image, cv::Size(0, 0), 0.7);
    const std::optional<PatternObservation> observation =
        DetectPattern(Save("charuco" + std::to_string(k) + ".png", image), spec);
    ASSERT_TRUE(observation) << k;
    EXPECT_EQ(observation->corner_ids.size(),
              static_cast<std::size_t>((spec.columns - 1) * (spec.rows - 1)));
    for (std::size_t i = 1; i < observation->corner_ids.size(); ++i) {
      EXPECT_LT(observation->corner_ids[i - 1], observation->corner_ids[i]);
    }
    const double worst = WorstCornerError(*observation, spec, H);
    EXPECT_LT(worst, 0.1) << "view " << k;
    worst_all = std::max(worst_all, worst);
  }
  std::printf("[charuco] worst corner error over %zu views: %.4f px\n", poses.size(), worst_all);
}

// Half of the board hidden: the corners still found carry the right ids.
TEST_F(DetectPatternTest, CharucoPartlyHidden) {
  const PatternSpec spec = Charuco();
  const Eigen::Matrix3d H = PlaneToImage(
      Pose(spec.columns * spec.square_m, spec.rows * spec.square_m, 0.6, 0.2, -0.2, 0.1));
  cv::Mat image = Render(H, CharucoShade(spec));
  cv::GaussianBlur(image, image, cv::Size(0, 0), 0.7);
  cv::rectangle(image, cv::Rect(0, 0, kWidth / 2, kHeight), cv::Scalar(128), cv::FILLED);
  const std::optional<PatternObservation> observation =
      DetectPattern(Save("hidden.png", image), spec);
  ASSERT_TRUE(observation);
  EXPECT_GE(observation->corner_ids.size(), 4u);
  EXPECT_LT(observation->corner_ids.size(),
            static_cast<std::size_t>((spec.columns - 1) * (spec.rows - 1)));
  EXPECT_LT(WorstCornerError(*observation, spec, H), 0.1);
}

TEST_F(DetectPatternTest, NoPatternIsNullopt) {
  cv::Mat blank(kHeight, kWidth, CV_8U, cv::Scalar(200));
  EXPECT_FALSE(DetectPattern(Save("blank.png", blank), Chessboard()));
  EXPECT_FALSE(DetectPattern(Save("blank_charuco.png", blank), Charuco()));
  cv::Mat noise(kHeight, kWidth, CV_8U);
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  EXPECT_FALSE(DetectPattern(Save("noise.png", noise), Chessboard()));
  EXPECT_FALSE(DetectPattern(Save("noise_charuco.png", noise), Charuco()));
  // A chessboard is not a ChArUco board (no markers).
  const PatternSpec spec = Chessboard();
  const cv::Mat board =
      Render(PlaneToImage(Pose((spec.columns - 1) * spec.square_m, (spec.rows - 1) * spec.square_m,
                               0.6, 0.1, 0.1, 0.0)),
             ChessboardShade(spec));
  EXPECT_FALSE(DetectPattern(Save("board.png", board), Charuco()));
}

// A manifest whose board size is off by a column finds no pattern (and quickly: OpenCV's
// classic detector alone searched such a view for minutes), while the right size still does.
TEST_F(DetectPatternTest, ABoardOfAnotherSizeIsNotFound) {
  const PatternSpec spec = Chessboard();
  const Eigen::Matrix3d H = PlaneToImage(Pose(
      (spec.columns - 1) * spec.square_m, (spec.rows - 1) * spec.square_m, 0.6, 0.2, -0.1, 0.1));
  cv::Mat image = Render(H, ChessboardShade(spec));
  cv::GaussianBlur(image, image, cv::Size(0, 0), 0.7);
  const std::filesystem::path path = Save("board.png", image);
  for (const int columns : {8, 10}) {
    PatternSpec other = spec;
    other.columns = columns;
    EXPECT_FALSE(DetectPattern(path, other)) << columns << " columns";
  }
  const std::optional<PatternObservation> right = DetectPattern(path, spec);
  ASSERT_TRUE(right);
  EXPECT_LT(WorstCornerError(*right, spec, H), 0.1);
}

TEST_F(DetectPatternTest, UnreadableImageThrowsNamingTheFile) {
  const std::filesystem::path missing = dir_ / "missing.png";
  try {
    DetectPattern(missing, Chessboard());
    ADD_FAILURE() << "missing file accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.png"), std::string::npos) << e.what();
  }
  const std::filesystem::path text = dir_ / "text.png";
  std::ofstream(text) << "not an image";
  EXPECT_THROW(DetectPattern(text, Chessboard()), Error);
  PatternSpec bad = Charuco();
  bad.dictionary = "DICT_9X9_1";
  const cv::Mat blank(64, 64, CV_8U, cv::Scalar(0));
  EXPECT_THROW(DetectPattern(Save("blank.png", blank), bad), Error);
}

}  // namespace
}  // namespace uwscan::scanner::calibration
