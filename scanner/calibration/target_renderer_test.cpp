#include "scanner/calibration/target_renderer.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "scanner/common/error.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"

namespace uwscan::scanner::calibration {
namespace {

RefractiveCamera WaterCamera() { return DefaultGalvoScannerModel().camera; }

// The same camera in air with the viewport index-matched: rays go straight through.
RefractiveCamera AirCamera() {
  RefractiveCamera camera = DefaultGalvoScannerModel().camera;
  camera.viewport.n_glass = 1.0;
  camera.viewport.n_water = 1.0;
  return camera;
}

// A board about `distance_m` ahead, turned about both image axes and rolled a little.
Eigen::Isometry3d BoardPose(const PatternSpec& spec, double distance_m) {
  const Eigen::Vector2d centre = BoardOf(spec).centre_O;
  Eigen::Isometry3d T_C_centre = Eigen::Isometry3d::Identity();
  T_C_centre.linear() = (Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitY()) *
                         Eigen::AngleAxisd(-0.25, Eigen::Vector3d::UnitX()) *
                         Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()))
                            .toRotationMatrix();
  T_C_centre.translation() = Eigen::Vector3d(0.03, -0.02, distance_m);
  return T_C_centre * Eigen::Translation3d(-centre.x(), -centre.y(), 0.0);
}

cv::Mat AsMat(const StripeFrame& frame) {
  return cv::Mat(frame.height_px, frame.width_px, CV_8U,
                 const_cast<std::uint8_t*>(frame.mono8.data()));
}

// Detected corners against the exact projections of their board points: the RMS distance, and
// the mean offset (a wrong pixel convention would show there).
struct CornerErrors {
  double rms_px = 0.0;
  Eigen::Vector2d mean_px = Eigen::Vector2d::Zero();
};
CornerErrors CompareCorners(const RefractiveCamera& camera, const PatternSpec& spec,
                            const Eigen::Isometry3d& T_C_O, const std::vector<int>& ids,
                            const std::vector<cv::Point2f>& corners) {
  const std::vector<Eigen::Vector3d> points = spec.CornerPoints_O();
  CornerErrors errors;
  double sum = 0.0;
  for (size_t k = 0; k < ids.size(); ++k) {
    const std::optional<Eigen::Vector2d> px =
        camera.ProjectPointInWater(T_C_O * points[static_cast<size_t>(ids[k])]);
    EXPECT_TRUE(px.has_value());
    if (!px) continue;
    const Eigen::Vector2d error = Eigen::Vector2d(corners[k].x, corners[k].y) - *px;
    sum += error.squaredNorm();
    errors.mean_px += error / static_cast<double>(ids.size());
  }
  errors.rms_px = std::sqrt(sum / static_cast<double>(ids.size()));
  return errors;
}

double ChessboardRms(const RefractiveCamera& camera, const char* label) {
  PatternSpec spec;  // 9 x 6 inner corners, 30 mm
  const Eigen::Isometry3d T_C_O = BoardPose(spec, 0.7);
  TargetRenderOptions options;
  options.seed = 11;
  const StripeFrame frame = RenderPattern(camera, spec, T_C_O, options);
  const cv::Mat image = AsMat(frame);
  std::vector<cv::Point2f> corners;
  const bool found =
      cv::findChessboardCorners(image, cv::Size(spec.columns, spec.rows), corners,
                                cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
  EXPECT_TRUE(found) << label;
  if (!found) return 1e9;
  cv::cornerSubPix(image, corners, cv::Size(7, 7), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
  EXPECT_EQ(corners.size(), static_cast<size_t>(spec.columns * spec.rows));
  // The finder's order is OpenCV's row by row, but it may start from either end of the board
  // (a chessboard looks the same turned by 180 degrees): take the order that fits.
  std::vector<int> ids(corners.size()), reversed(corners.size());
  for (size_t k = 0; k < ids.size(); ++k) {
    ids[k] = static_cast<int>(k);
    reversed[k] = static_cast<int>(ids.size() - 1 - k);
  }
  CornerErrors errors = CompareCorners(camera, spec, T_C_O, ids, corners);
  const CornerErrors other = CompareCorners(camera, spec, T_C_O, reversed, corners);
  if (other.rms_px < errors.rms_px) errors = other;
  EXPECT_LT(errors.mean_px.norm(), 0.03) << label;
  std::printf(
      "[ chessboard %s ] %zu corners, RMS %.4f px against exact projection, mean "
      "(%.4f, %.4f) px\n",
      label, corners.size(), errors.rms_px, errors.mean_px.x(), errors.mean_px.y());
  return errors.rms_px;
}

TEST(TargetRenderer, ChessboardCornersMatchExactProjectionInAir) {
  EXPECT_LT(ChessboardRms(AirCamera(), "air"), 0.1);
}

TEST(TargetRenderer, ChessboardCornersMatchExactProjectionUnderWater) {
  EXPECT_LT(ChessboardRms(WaterCamera(), "water"), 0.1);
}

double CharucoRms(const RefractiveCamera& camera, const char* label) {
  PatternSpec spec;
  spec.type = PatternType::kCharuco;
  spec.columns = 8;
  spec.rows = 6;
  spec.square_m = 0.04;
  spec.marker_m = 0.03;
  const Eigen::Isometry3d T_C_O = BoardPose(spec, 0.8);
  TargetRenderOptions options;
  options.seed = 5;
  const StripeFrame frame = RenderPattern(camera, spec, T_C_O, options);
  const cv::Mat image = AsMat(frame);
  const cv::Ptr<cv::aruco::Dictionary> dictionary =
      cv::aruco::getPredefinedDictionary(ArucoDictionaryId(spec.dictionary));
  const cv::Ptr<cv::aruco::CharucoBoard> board =
      cv::aruco::CharucoBoard::create(spec.columns, spec.rows, static_cast<float>(spec.square_m),
                                      static_cast<float>(spec.marker_m), dictionary);
  std::vector<std::vector<cv::Point2f>> markers;
  std::vector<int> marker_ids;
  cv::aruco::detectMarkers(image, dictionary, markers, marker_ids);
  EXPECT_EQ(marker_ids.size(), static_cast<size_t>(spec.columns * spec.rows / 2)) << label;
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  cv::aruco::interpolateCornersCharuco(markers, marker_ids, image, board, corners, ids);
  EXPECT_EQ(ids.size(), static_cast<size_t>((spec.columns - 1) * (spec.rows - 1))) << label;
  if (ids.empty()) return 1e9;
  // OpenCV's own board points are ours, id for id (same frame, same order).
  const std::vector<Eigen::Vector3d> points = spec.CornerPoints_O();
  EXPECT_EQ(points.size(), board->chessboardCorners.size());
  for (size_t k = 0; k < points.size() && k < board->chessboardCorners.size(); ++k) {
    const cv::Point3f& p = board->chessboardCorners[k];
    EXPECT_NEAR((points[k] - Eigen::Vector3d(p.x, p.y, p.z)).norm(), 0.0, 1e-6) << k;
  }
  // OpenCV 4.6's interpolateCornersCharuco shifts its corners by +0.5 px in x and y: it moves
  // them by -0.5 px before cornerSubPix and back by +0.5 px after, although cornerSubPix
  // already works in the pixel-centre convention (opencv_contrib PR 3024; undone upstream by
  // opencv PR 28380). findChessboardCorners and projectPoints have no such shift.
  const CornerErrors shifted = CompareCorners(camera, spec, T_C_O, ids, corners);
  EXPECT_NEAR(shifted.mean_px.x(), 0.5, 0.1) << label;
  EXPECT_NEAR(shifted.mean_px.y(), 0.5, 0.1) << label;
  for (cv::Point2f& c : corners) c -= cv::Point2f(0.5f, 0.5f);
  const double rms = CompareCorners(camera, spec, T_C_O, ids, corners).rms_px;
  std::printf(
      "[ charuco %s ] %zu corners, OpenCV's shift (%.3f, %.3f) px, RMS %.4f px against "
      "exact projection once it is removed\n",
      label, ids.size(), shifted.mean_px.x(), shifted.mean_px.y(), rms);
  return rms;
}

TEST(TargetRenderer, CharucoCornerIdsMatchCornerPointsInAir) {
  EXPECT_LT(CharucoRms(AirCamera(), "air"), 0.1);
}

TEST(TargetRenderer, CharucoCornerIdsMatchCornerPointsUnderWater) {
  EXPECT_LT(CharucoRms(WaterCamera(), "water"), 0.1);
}

TEST(TargetRenderer, SameSeedSameImageWhateverTheThreads) {
  const RefractiveCamera camera = WaterCamera();
  PatternSpec spec;
  const Eigen::Isometry3d T_C_O = BoardPose(spec, 0.7);
  TargetRenderOptions options;
  options.seed = 3;
  const TargetRenderer renderer(camera);
  const auto start = std::chrono::steady_clock::now();
  const StripeFrame a = renderer.Render(spec, T_C_O, options);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("[ render ] %dx%d, supersampling %d, %d threads: %.3f s\n", a.width_px, a.height_px,
              options.supersampling, omp_get_max_threads(), seconds);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(threads == 1 ? 2 : 1);
  const StripeFrame b = renderer.Render(spec, T_C_O, options);
  omp_set_num_threads(threads);
  EXPECT_EQ(a.mono8, b.mono8);
  options.seed = 4;
  EXPECT_NE(renderer.Render(spec, T_C_O, options).mono8, a.mono8);
}

TEST(TargetRenderer, BoardOutOfViewOrBackwardsShowsBlackLevel) {
  RefractiveCamera camera = AirCamera();
  camera.camera.width_px = 64;
  camera.camera.height_px = 48;
  camera.camera.cx_px = 31.5;
  camera.camera.cy_px = 23.5;
  PatternSpec spec;
  TargetRenderOptions options;
  options.noise_sigma = 0.0;
  options.blur_sigma_px = 0.0;
  Eigen::Isometry3d behind = Eigen::Isometry3d::Identity();
  behind.translation() = Eigen::Vector3d(0.0, 0.0, -1.0);
  for (const std::uint8_t v : RenderPattern(camera, spec, behind, options).mono8) {
    ASSERT_EQ(v, 20);
  }
  // Facing the camera with its back: z_O towards the camera.
  Eigen::Isometry3d back = Eigen::Isometry3d::Identity();
  back.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
  back.translation() = Eigen::Vector3d(0.0, 0.0, 1.0);
  for (const std::uint8_t v : RenderPattern(camera, spec, back, options).mono8) {
    ASSERT_EQ(v, 20);
  }
  // The white margin fills a camera close to the board's corner, front on.
  Eigen::Isometry3d front = Eigen::Isometry3d::Identity();
  front.translation() = Eigen::Vector3d(0.0, 0.0, 0.5) - Eigen::Vector3d(-0.045, -0.045, 0.0);
  const StripeFrame margin = RenderPattern(camera, spec, front, options);
  EXPECT_EQ(margin.mono8[static_cast<size_t>(24 * 64 + 32)], 200);
}

TEST(TargetRenderer, Mono16UsesItsOwnLevels) {
  RefractiveCamera camera = AirCamera();
  PatternSpec spec;
  TargetRenderOptions options;
  options.format = PixelFormat::kMono16;
  options.white_level = 50000;
  options.black_level = 5000;
  options.noise_sigma = 100;
  const StripeFrame frame = RenderPattern(camera, spec, BoardPose(spec, 0.7), options);
  ASSERT_EQ(frame.mono16.size(), static_cast<size_t>(frame.width_px * frame.height_px));
  EXPECT_TRUE(frame.mono8.empty());
  const auto [lo, hi] = std::minmax_element(frame.mono16.begin(), frame.mono16.end());
  EXPECT_LT(*lo, 6000);
  EXPECT_GT(*hi, 49000);
}

TEST(TargetRenderer, DotCentroidIsItsCentre) {
  TargetRenderOptions options;
  options.noise_sigma = 0.0;
  options.black_level = 0.0;
  options.format = PixelFormat::kMono16;
  options.white_level = 60000;
  const Eigen::Vector2d centre(100.37, 61.81);
  const StripeFrame dot = RenderDot(200, 120, centre, 1.7, 40000.0, options);
  double sum = 0.0;
  Eigen::Vector2d moment = Eigen::Vector2d::Zero();
  int peak = 0;
  for (int v = 0; v < dot.height_px; ++v) {
    for (int u = 0; u < dot.width_px; ++u) {
      const double value = dot.mono16[static_cast<size_t>(v) * dot.width_px + u];
      peak = std::max(peak, static_cast<int>(value));
      sum += value;
      moment += value * Eigen::Vector2d(u, v);
    }
  }
  EXPECT_LT((moment / sum - centre).norm(), 0.01);
  EXPECT_NEAR(sum, 40000.0 * 2.0 * M_PI * 1.7 * 1.7, 0.001 * sum);
  EXPECT_GT(peak, 30000);
}

TEST(TargetRenderer, RejectsUnusableOptionsAndBoards) {
  TargetRenderOptions options;
  options.supersampling = 0;
  EXPECT_THROW(options.Check(), Error);
  options = TargetRenderOptions{};
  options.white_level = 300;  // beyond Mono8
  EXPECT_THROW(options.Check(), Error);
  options = TargetRenderOptions{};
  options.board_size_m = Eigen::Vector2d(0.6, 0.0);
  EXPECT_THROW(options.Check(), Error);
  PatternSpec spec;  // 9 x 6 x 30 mm: squares 0.3 x 0.21 m, with margin 0.36 x 0.27 m
  EXPECT_THROW(BoardOf(spec, Eigen::Vector2d(0.33, 0.3)), Error);
  EXPECT_NO_THROW(BoardOf(spec, Eigen::Vector2d(0.36, 0.27)));
  const BoardGeometry board = BoardOf(spec);
  EXPECT_NEAR(board.size_m.x(), 0.36, 1e-12);
  EXPECT_NEAR(board.centre_O.y(), 0.075, 1e-12);
  EXPECT_THROW(ArucoDictionaryId("DICT_4X4_51"), Error);
  EXPECT_EQ(ArucoDictionaryId("DICT_4X4_50"), 0);
  spec.type = PatternType::kCharuco;
  spec.columns = 12;
  spec.rows = 10;  // 60 markers: more than DICT_4X4_50 holds
  EXPECT_THROW(RenderPattern(AirCamera(), spec, Eigen::Isometry3d::Identity(), {}), Error);
}

}  // namespace
}  // namespace uwscan::scanner::calibration
