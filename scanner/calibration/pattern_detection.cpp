#include "scanner/calibration/pattern_detection.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/aruco.hpp>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "scanner/calibration/target_renderer.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::scanner::calibration {
namespace {

constexpr int kMinCharucoCorners = 4;

cv::aruco::PREDEFINED_DICTIONARY_NAME DictionaryId(const std::string& name) {
  return static_cast<cv::aruco::PREDEFINED_DICTIONARY_NAME>(ArucoDictionaryId(name));
}

// The image as 8-bit grey for the detectors, and at full depth (8-bit or float) for the
// sub-pixel refinement. Empty `detect` means a uniform image: nothing to find.
struct GreyImages {
  cv::Mat detect;
  cv::Mat refine;
};

GreyImages LoadGrey(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    // Checked here rather than left to cv::imread, which would also log to stderr.
    throw Error("DetectPattern: cannot read image '" + file + "': no such file");
  }
  cv::Mat raw;
  try {
    raw = cv::imread(file, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw Error("DetectPattern: cannot read image '" + file + "': " + e.what());
  }
  if (raw.empty()) {
    throw Error("DetectPattern: cannot read image '" + file +
                "' (missing, unreadable or not an image format OpenCV knows)");
  }
  if (raw.depth() != CV_8U && raw.depth() != CV_16U) {
    throw Error("DetectPattern: image '" + file +
                "' has an unsupported pixel depth (expected 8 or 16 bits per channel)");
  }
  cv::Mat grey;
  switch (raw.channels()) {
    case 1:
      grey = raw;
      break;
    case 3:
      cv::cvtColor(raw, grey, cv::COLOR_BGR2GRAY);
      break;
    case 4:
      cv::cvtColor(raw, grey, cv::COLOR_BGRA2GRAY);
      break;
    default:
      throw Error("DetectPattern: image '" + file + "' has " + std::to_string(raw.channels()) +
                  " channels (expected 1, 3 or 4)");
  }
  GreyImages images;
  if (grey.depth() == CV_8U) {
    images.detect = grey;
    images.refine = grey;
    return images;
  }
  // 16 bits: a fixed shift would leave a 12-bit image at 1/16 of the 8-bit range; stretch the
  // used range instead. The refinement keeps every bit (cornerSubPix takes 32-bit float).
  double lo = 0.0;
  double hi = 0.0;
  cv::minMaxLoc(grey, &lo, &hi);
  if (!(hi > lo)) return images;
  grey.convertTo(images.detect, CV_8U, 255.0 / (hi - lo), -255.0 * lo / (hi - lo));
  grey.convertTo(images.refine, CV_32F);
  return images;
}

// Whether a chessboard of `size` inner corners is in the image, found without the classic
// detector's search at full size: given a size the board does not have (a manifest's columns off
// by one), that search took 237 s on a 2048x1088 view, where at half size it gave up in 1.4 s and
// the sector-based detector at full size in 0.5 s (the right size: 0.002 s at half size).
bool ChessboardSeen(const cv::Mat& image, const cv::Size& size, int flags) {
  cv::Mat half;
  cv::resize(image, half, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
  std::vector<cv::Point2f> corners;
  if (cv::findChessboardCorners(half, size, corners, flags)) return true;
  return cv::findChessboardCornersSB(image, size, corners);  // squares too small at half size
}

std::optional<PatternObservation> DetectChessboard(const GreyImages& images,
                                                   const PatternSpec& spec,
                                                   const std::string& file) {
  const cv::Size size(spec.columns, spec.rows);
  std::vector<cv::Point2f> corners;
  const int flags =
      cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK;
  // The corners themselves come from the classic detector at full size (0.06 s once the board is
  // known to be there), whose convention the refinement and the rest of calibration follow.
  if (!ChessboardSeen(images.detect, size, flags)) return std::nullopt;
  if (!cv::findChessboardCorners(images.detect, size, corners, flags)) return std::nullopt;

  // The window half-size: 0.4 of the smallest spacing between neighbouring corners, so that
  // it never reaches another corner (perspective shrinks the far squares).
  double spacing = std::numeric_limits<double>::infinity();
  for (int y = 0; y < spec.rows; ++y) {
    for (int x = 0; x < spec.columns; ++x) {
      const cv::Point2f& c = corners[static_cast<std::size_t>(y * spec.columns + x)];
      if (x + 1 < spec.columns) {
        spacing = std::min(
            spacing, cv::norm(corners[static_cast<std::size_t>(y * spec.columns + x + 1)] - c));
      }
      if (y + 1 < spec.rows) {
        spacing = std::min(
            spacing, cv::norm(corners[static_cast<std::size_t>((y + 1) * spec.columns + x)] - c));
      }
    }
  }
  const int half = std::clamp(static_cast<int>(0.4 * spacing), 3, 25);
  cv::cornerSubPix(images.refine, corners, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-4));

  PatternObservation observation;
  observation.image = file;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    observation.corner_ids.push_back(static_cast<int>(i));
    observation.corners_px.emplace_back(corners[i].x, corners[i].y);
  }
  return observation;
}

// Mean edge length of a detected marker, pixels.
double MarkerSide(const std::vector<cv::Point2f>& quad) {
  double sum = 0.0;
  for (std::size_t i = 0; i < 4; ++i) sum += cv::norm(quad[(i + 1) % 4] - quad[i]);
  return sum / 4.0;
}

// A copy of `image` with every detected marker painted over, slightly enlarged (to cover its
// blurred edge), in the mean grey of a thin ring just outside it: the white of its square.
// The enlargement stays well inside the white margin between marker and square edge.
cv::Mat EraseMarkers(const cv::Mat& image, const std::vector<std::vector<cv::Point2f>>& markers,
                     const PatternSpec& spec) {
  constexpr int kShift = 4;  // fillConvexPoly's fractional bits
  const double margin_per_side = (spec.square_m - spec.marker_m) / (2.0 * spec.marker_m);
  cv::Mat erased = image.clone();
  cv::Mat inner(image.size(), CV_8U);
  cv::Mat ring(image.size(), CV_8U);
  for (const std::vector<cv::Point2f>& quad : markers) {
    const cv::Point2f centre = 0.25F * (quad[0] + quad[1] + quad[2] + quad[3]);
    const double grow = std::clamp(0.3 * margin_per_side * MarkerSide(quad), 1.0, 3.0);
    // Moving each corner along its diagonal by sqrt(2) d moves both edges out by about d.
    const auto grown = [&](double d) {
      std::vector<cv::Point> points;
      for (const cv::Point2f& c : quad) {
        const cv::Point2f out = c - centre;
        const double scale = 1.0 + std::sqrt(2.0) * d / cv::norm(out);
        points.emplace_back(
            static_cast<int>(std::lround((centre.x + scale * out.x) * (1 << kShift))),
            static_cast<int>(std::lround((centre.y + scale * out.y) * (1 << kShift))));
      }
      return points;
    };
    const std::vector<cv::Point> cover = grown(grow);
    inner.setTo(0);
    ring.setTo(0);
    cv::fillConvexPoly(inner, cover, cv::Scalar(255), cv::LINE_8, kShift);
    cv::fillConvexPoly(ring, grown(grow + 2.0), cv::Scalar(255), cv::LINE_8, kShift);
    ring.setTo(0, inner);
    const cv::Scalar white = cv::mean(image, ring);
    cv::fillConvexPoly(erased, cover, white, cv::LINE_8, kShift);
  }
  return erased;
}

std::optional<PatternObservation> DetectCharuco(const GreyImages& images, const PatternSpec& spec,
                                                const std::string& file) {
  const cv::Ptr<cv::aruco::Dictionary> dictionary =
      cv::aruco::getPredefinedDictionary(DictionaryId(spec.dictionary));
  const cv::Ptr<cv::aruco::CharucoBoard> board =
      cv::aruco::CharucoBoard::create(spec.columns, spec.rows, static_cast<float>(spec.square_m),
                                      static_cast<float>(spec.marker_m), dictionary);
  const cv::Ptr<cv::aruco::DetectorParameters> parameters = cv::aruco::DetectorParameters::create();
  std::vector<std::vector<cv::Point2f>> marker_corners;
  std::vector<std::vector<cv::Point2f>> rejected;
  std::vector<int> marker_ids;
  cv::aruco::detectMarkers(images.detect, dictionary, marker_corners, marker_ids, parameters,
                           rejected);
  if (marker_ids.empty()) return std::nullopt;
  // Markers missed at first (blur, glare) are looked for again where the board says they are.
  const cv::Ptr<cv::aruco::Board> as_board = board;
  cv::aruco::refineDetectedMarkers(images.detect, as_board, marker_corners, marker_ids, rejected);

  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, images.detect, board, corners,
                                       ids);
  if (static_cast<int>(ids.size()) < kMinCharucoCorners) return std::nullopt;

  // OpenCV 4.6 returns ChArUco corners 0.5 px down and right of the saddle points (its
  // refinement shifts into and back out of another pixel convention: opencv_contrib PR 3024,
  // opencv issue 25539), refined with windows kept inside the white margins around the markers
  // and stopped at 0.1 px: worst errors of 0.15 px on clean synthetic boards. Refine again, in
  // the convention of cornerSubPix and findChessboardCorners, on a copy with the markers
  // painted over in their squares' white: the saddles then look like a chessboard's and take
  // the same window, 0.4 of a square. Starting from OpenCV's corner shifted back (a version
  // without the shift converges to the same point).
  const cv::Mat erased = EraseMarkers(images.refine, marker_corners, spec);
  for (std::size_t k = 0; k < corners.size(); ++k) {
    // The square's size in pixels here, from the nearest marker's size.
    double nearest = std::numeric_limits<double>::infinity();
    double square_px = 0.0;
    for (const std::vector<cv::Point2f>& marker : marker_corners) {
      const cv::Point2f centre = 0.25F * (marker[0] + marker[1] + marker[2] + marker[3]);
      const double distance = cv::norm(centre - corners[k]);
      if (distance < nearest) {
        nearest = distance;
        square_px = MarkerSide(marker) * spec.square_m / spec.marker_m;
      }
    }
    const int half = std::clamp(static_cast<int>(0.4 * square_px), 2, 25);
    std::vector<cv::Point2f> corner = {corners[k] - cv::Point2f(0.5F, 0.5F)};
    cv::cornerSubPix(erased, corner, cv::Size(half, half), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-4));
    corners[k] = corner[0];
  }

  std::vector<std::size_t> order(ids.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&ids](std::size_t a, std::size_t b) { return ids[a] < ids[b]; });
  PatternObservation observation;
  observation.image = file;
  for (const std::size_t k : order) {
    observation.corner_ids.push_back(ids[k]);
    observation.corners_px.emplace_back(corners[k].x, corners[k].y);
  }
  return observation;
}

}  // namespace

std::optional<PatternObservation> DetectPattern(const std::filesystem::path& image,
                                                const PatternSpec& spec) {
  spec.Check();
  if (spec.type == PatternType::kCharuco) DictionaryId(spec.dictionary);  // before any I/O
  const std::string file = image.string();
  const GreyImages images = LoadGrey(image);
  if (images.detect.empty()) return std::nullopt;  // a uniform image
  try {
    return spec.type == PatternType::kChessboard ? DetectChessboard(images, spec, file)
                                                 : DetectCharuco(images, spec, file);
  } catch (const cv::Exception& e) {
    throw Error("DetectPattern: OpenCV failed on '" + file + "': " + e.what());
  }
}

}  // namespace uwscan::scanner::calibration
