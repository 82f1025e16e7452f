#include "scanner/calibration/target_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner::calibration {
namespace {

// ChArUco texture resolution: texels per square edge, and a cap on the whole texture so that
// large boards stay affordable. Square edges fall on texel edges exactly (draw() is given a
// whole number of texels per square), so nearest-texel lookup places them without error; only
// marker edges are quantised, and only marker decoding sees those.
constexpr int kTexelsPerSquare = 240;
constexpr double kMaxTexels = 40e6;

std::uint64_t SplitMix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// What the board shows at a point of its plane: 1 white paper, 0 black print, -1 off the board.
class BoardTexture {
 public:
  BoardTexture(const PatternSpec& spec, const BoardGeometry& board) : spec_(spec), board_(board) {
    if (spec.type != PatternType::kCharuco) return;
    const cv::Ptr<cv::aruco::Dictionary> dictionary =
        cv::aruco::getPredefinedDictionary(ArucoDictionaryId(spec.dictionary));
    const int markers = spec.columns * spec.rows / 2;
    if (markers > dictionary->bytesList.rows) {
      throw Error("pattern: a " + std::to_string(spec.columns) + "x" + std::to_string(spec.rows) +
                  " ChArUco board needs " + std::to_string(markers) + " markers, dictionary " +
                  spec.dictionary + " has " + std::to_string(dictionary->bytesList.rows));
    }
    texels_ = std::min<int>(kTexelsPerSquare,
                            static_cast<int>(std::sqrt(kMaxTexels / (spec.columns * spec.rows))));
    const cv::Ptr<cv::aruco::CharucoBoard> charuco =
        cv::aruco::CharucoBoard::create(spec.columns, spec.rows, static_cast<float>(spec.square_m),
                                        static_cast<float>(spec.marker_m), dictionary);
    charuco->draw(cv::Size(spec.columns * texels_, spec.rows * texels_), texture_, 0, 1);
    texels_per_m_ = texels_ / spec.square_m;
  }

  int At(double x_O, double y_O) const {
    if (!board_.Contains(Eigen::Vector2d(x_O, y_O))) return -1;
    const double s = spec_.square_m;
    if (spec_.type == PatternType::kChessboard) {
      // Squares (i, j) from -1 to columns - 1 (rows - 1): columns + 1 squares around columns
      // inner corners; (-1, -1), the top-left one, is black.
      const double fx = std::floor(x_O / s), fy = std::floor(y_O / s);
      if (fx < -1 || fy < -1 || fx > spec_.columns - 1 || fy > spec_.rows - 1) return 1;
      return (static_cast<long>(fx) + static_cast<long>(fy)) % 2 == 0 ? 0 : 1;
    }
    const int col = static_cast<int>(std::floor(x_O * texels_per_m_));
    const int row = static_cast<int>(std::floor(y_O * texels_per_m_));
    if (col < 0 || row < 0 || col >= texture_.cols || row >= texture_.rows) return 1;
    return texture_.at<std::uint8_t>(row, col) > 127 ? 1 : 0;
  }

 private:
  PatternSpec spec_;
  BoardGeometry board_;
  cv::Mat texture_;  // ChArUco print, row 0 at y_O = 0, 255 white
  int texels_ = 0;
  double texels_per_m_ = 0.0;
};

// Adds noise (one generator per row, seeded from the image seed and the row, so the image does
// not depend on the thread count), rounds and clips.
StripeFrame Quantise(const cv::Mat& levels, const TargetRenderOptions& options) {
  StripeFrame frame;
  frame.width_px = levels.cols;
  frame.height_px = levels.rows;
  frame.format = options.format;
  const size_t count = static_cast<size_t>(levels.cols) * levels.rows;
  if (options.format == PixelFormat::kMono8) {
    frame.mono8.resize(count);
  } else {
    frame.mono16.resize(count);
  }
  const double max_value = MaxPixelValue(options.format);
#pragma omp parallel for schedule(static)
  for (int v = 0; v < levels.rows; ++v) {
    std::mt19937_64 rng(SplitMix(options.seed ^ SplitMix(static_cast<std::uint64_t>(v))));
    std::normal_distribution<double> normal(0.0, 1.0);
    const float* in = levels.ptr<float>(v);
    for (int u = 0; u < levels.cols; ++u) {
      double value = in[u];
      if (options.noise_sigma > 0.0) value += options.noise_sigma * normal(rng);
      value = std::clamp(std::round(value), 0.0, max_value);
      const size_t i = static_cast<size_t>(v) * levels.cols + u;
      if (options.format == PixelFormat::kMono8) {
        frame.mono8[i] = static_cast<std::uint8_t>(value);
      } else {
        frame.mono16[i] = static_cast<std::uint16_t>(value);
      }
    }
  }
  return frame;
}

}  // namespace

int ArucoDictionaryId(const std::string& name) {
  struct Entry {
    const char* name;
    cv::aruco::PREDEFINED_DICTIONARY_NAME id;
  };
  static const Entry kDictionaries[] = {
      {"DICT_4X4_50", cv::aruco::DICT_4X4_50},
      {"DICT_4X4_100", cv::aruco::DICT_4X4_100},
      {"DICT_4X4_250", cv::aruco::DICT_4X4_250},
      {"DICT_4X4_1000", cv::aruco::DICT_4X4_1000},
      {"DICT_5X5_50", cv::aruco::DICT_5X5_50},
      {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
      {"DICT_5X5_250", cv::aruco::DICT_5X5_250},
      {"DICT_5X5_1000", cv::aruco::DICT_5X5_1000},
      {"DICT_6X6_50", cv::aruco::DICT_6X6_50},
      {"DICT_6X6_100", cv::aruco::DICT_6X6_100},
      {"DICT_6X6_250", cv::aruco::DICT_6X6_250},
      {"DICT_6X6_1000", cv::aruco::DICT_6X6_1000},
      {"DICT_7X7_50", cv::aruco::DICT_7X7_50},
      {"DICT_7X7_100", cv::aruco::DICT_7X7_100},
      {"DICT_7X7_250", cv::aruco::DICT_7X7_250},
      {"DICT_7X7_1000", cv::aruco::DICT_7X7_1000},
      {"DICT_ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL},
      {"DICT_APRILTAG_16h5", cv::aruco::DICT_APRILTAG_16h5},
      {"DICT_APRILTAG_25h9", cv::aruco::DICT_APRILTAG_25h9},
      {"DICT_APRILTAG_36h10", cv::aruco::DICT_APRILTAG_36h10},
      {"DICT_APRILTAG_36h11", cv::aruco::DICT_APRILTAG_36h11},
  };
  std::string known;
  for (const Entry& e : kDictionaries) {
    if (name == e.name) return static_cast<int>(e.id);
    known += std::string(known.empty() ? "" : ", ") + e.name;
  }
  throw Error("pattern: dictionary '" + name + "' is not an OpenCV ArUco dictionary (" + known +
              ")");
}

Eigen::AlignedBox2d PatternExtent_O(const PatternSpec& spec) {
  spec.Check();
  const double s = spec.square_m;
  if (spec.type == PatternType::kChessboard) {
    return Eigen::AlignedBox2d(Eigen::Vector2d(-s, -s),
                               Eigen::Vector2d(spec.columns * s, spec.rows * s));
  }
  return Eigen::AlignedBox2d(Eigen::Vector2d::Zero(),
                             Eigen::Vector2d(spec.columns * s, spec.rows * s));
}

BoardGeometry BoardOf(const PatternSpec& spec, const Eigen::Vector2d& board_size_m) {
  const Eigen::AlignedBox2d extent = PatternExtent_O(spec);
  const Eigen::Vector2d with_margin =
      extent.sizes() + Eigen::Vector2d::Constant(2.0 * spec.square_m);
  BoardGeometry board;
  board.centre_O = extent.center();
  if (board_size_m.isZero()) {
    board.size_m = with_margin;
    return board;
  }
  // The chessboard finder needs light paper around the outer squares; ChArUco markers are
  // found on their own, so its board may end at the squares.
  const Eigen::Vector2d needed =
      spec.type == PatternType::kChessboard ? with_margin : extent.sizes();
  if (!(board_size_m.array() >= needed.array() - 1e-12).all()) {
    throw Error("board_size_m: [" + std::to_string(board_size_m.x()) + ", " +
                std::to_string(board_size_m.y()) + "] m does not hold the pattern (needs [" +
                std::to_string(needed.x()) + ", " + std::to_string(needed.y()) + "] m)");
  }
  board.size_m = board_size_m;
  return board;
}

void TargetRenderOptions::Check() const {
  const OptionChecks check("TargetRenderOptions");
  check.InRange("supersampling", supersampling, 1, 16);
  check.InRange("blur_sigma_px", blur_sigma_px, 0.0, 20.0, Interval::kClosed, "px");
  check.AtLeast("black_level", black_level, 0.0, "image units");
  const double max_value = MaxPixelValue(format);
  check.Require(white_level > black_level && white_level <= max_value, "white_level",
                "> black_level (" + OptionValueText(black_level) +
                    ") and <= " + OptionValueText(max_value) + " image units",
                white_level);
  check.NonNegative("noise_sigma", noise_sigma, "image units");
  check.Require(board_size_m.allFinite() && (board_size_m.array() >= 0.0).all() &&
                    (board_size_m.x() > 0.0) == (board_size_m.y() > 0.0),
                "board_size_m", "[x, y] both > 0, or both 0 (the default board), metres",
                OptionPairText(board_size_m.x(), board_size_m.y()));
}

TargetRenderer::TargetRenderer(const RefractiveCamera& camera) : camera_(camera), rays_(camera) {}

StripeFrame TargetRenderer::Render(const PatternSpec& spec, const Eigen::Isometry3d& T_C_O,
                                   const TargetRenderOptions& options) const {
  options.Check();
  spec.Check();
  const BoardTexture texture(spec, BoardOf(spec, options.board_size_m));
  const int width = camera_.camera.width_px, height = camera_.camera.height_px;
  const int S = options.supersampling;
  const Eigen::Vector3d origin_O = T_C_O.translation();
  const Eigen::Vector3d x_O = T_C_O.linear().col(0), y_O = T_C_O.linear().col(1);
  const Eigen::Vector3d normal = T_C_O.linear().col(2);  // into the board, away from its front
  const float level[2] = {static_cast<float>(options.black_level),
                          static_cast<float>(options.white_level)};
  const float miss = level[0];
  const float weight = 1.0f / static_cast<float>(S * S);

  cv::Mat levels(height, width, CV_32F);
#pragma omp parallel for schedule(dynamic, 4)
  for (int v = 0; v < height; ++v) {
    float* out = levels.ptr<float>(v);
    for (int u = 0; u < width; ++u) {
      float sum = 0.0f;
      for (int j = 0; j < S; ++j) {
        for (int i = 0; i < S; ++i) {
          // A sheared grid: the S^2 samples take S^2 distinct columns and rows (n-rooks), so an
          // edge close to an image axis, the usual case on a chessboard, moves the pixel's mean
          // in steps of 1/S^2 px rather than the 1/S of a square grid, and the corner finders
          // see far less of the sampling's staircase.
          const double uu = u - 0.5 + (i * S + j + 0.5) / (S * S);
          const double vv = v - 0.5 + (j * S + i + 0.5) / (S * S);
          Ray ray;
          // The front faces the camera when the ray runs along +z_O; anything else (the back,
          // a grazing ray, a board behind the camera) shows no print.
          float sample = miss;
          if (rays_.Lookup(uu, vv, &ray)) {
            const double along = normal.dot(ray.direction);
            const double t = normal.dot(origin_O - ray.origin) / along;
            if (along > 1e-12 && t > 0.0) {
              const Eigen::Vector3d d = ray.origin + t * ray.direction - origin_O;
              const int albedo = texture.At(x_O.dot(d), y_O.dot(d));
              if (albedo >= 0) sample = level[albedo];
            }
          }
          sum += sample;
        }
      }
      out[u] = sum * weight;
    }
  }
  if (options.blur_sigma_px > 0.0) {
    cv::GaussianBlur(levels, levels, cv::Size(0, 0), options.blur_sigma_px, options.blur_sigma_px,
                     cv::BORDER_REFLECT);
  }
  return Quantise(levels, options);
}

StripeFrame RenderPattern(const RefractiveCamera& camera, const PatternSpec& spec,
                          const Eigen::Isometry3d& T_C_O, const TargetRenderOptions& options) {
  return TargetRenderer(camera).Render(spec, T_C_O, options);
}

StripeFrame RenderDot(int width_px, int height_px, const Eigen::Vector2d& centre_px,
                      double sigma_px, double amplitude, const TargetRenderOptions& options) {
  options.Check();
  if (width_px < 1 || height_px < 1) throw Error("dot render: image size must be >= 1x1 px");
  if (!centre_px.allFinite() || !(sigma_px > 0.0 && sigma_px < 1e3) ||
      !(amplitude >= 0.0 && std::isfinite(amplitude))) {
    throw Error("dot render: expected a finite centre, sigma_px in (0, 1000) and amplitude >= 0");
  }
  cv::Mat levels(height_px, width_px, CV_32F, cv::Scalar(options.black_level));
  // The pixel integrals of the Gaussian factor into a column and a row term.
  const double reach = 6.0 * sigma_px + 1.0;
  const int u0 = std::max(0, static_cast<int>(std::floor(centre_px.x() - reach)));
  const int u1 = std::min(width_px - 1, static_cast<int>(std::ceil(centre_px.x() + reach)));
  const int v0 = std::max(0, static_cast<int>(std::floor(centre_px.y() - reach)));
  const int v1 = std::min(height_px - 1, static_cast<int>(std::ceil(centre_px.y() + reach)));
  const double inv = 1.0 / (std::sqrt(2.0) * sigma_px);
  auto integral = [&](int i, double c) {
    return 0.5 * (std::erf((i + 0.5 - c) * inv) - std::erf((i - 0.5 - c) * inv));
  };
  const double scale = amplitude * 2.0 * M_PI * sigma_px * sigma_px;
  for (int v = v0; v <= v1; ++v) {
    const double row = scale * integral(v, centre_px.y());
    float* out = levels.ptr<float>(v);
    for (int u = u0; u <= u1; ++u) out[u] += static_cast<float>(row * integral(u, centre_px.x()));
  }
  return Quantise(levels, options);
}

}  // namespace uwscan::scanner::calibration
