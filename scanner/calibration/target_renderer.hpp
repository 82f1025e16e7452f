#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>

#include "scanner/calibration/observations.hpp"
#include "scanner/optics/camera_ray_table.hpp"
#include "scanner/optics/refractive_camera.hpp"
#include "scanner/stripe/stripe_render.hpp"

namespace uwscan::scanner::calibration {

// Camera images of calibration targets, rendered through the camera's viewport so that every
// calibration step can be checked against the truth that made its images.
//
// The board. The pattern is printed on white paper glued to a flat board; the pattern frame
// {O} is PatternSpec's (x_O along the corner rows, y_O down the printed pattern, z_O out of
// the board's back, so a camera sees the front from -z_O). A chessboard of `columns` x `rows`
// inner corners has (columns + 1) x (rows + 1) squares, the top-left one black, starting one
// square before the first inner corner; a ChArUco board is drawn by OpenCV
// (cv::aruco::CharucoBoard::draw), its top-left corner at the origin of {O}. Around the pattern
// the paper stays white: one square wide by default (OpenCV's chessboard finder needs a light
// border around the outer squares), or out to `board_size_m`, centred on the pattern.

// OpenCV's predefined ArUco dictionary (cv::aruco::PREDEFINED_DICTIONARY_NAME) of a name such
// as "DICT_4X4_50", as an int so that OpenCV stays out of this header. Throws uwscan::Error
// listing the known names.
int ArucoDictionaryId(const std::string& name);

struct BoardGeometry {
  Eigen::Vector2d centre_O = Eigen::Vector2d::Zero();  // middle of the pattern, metres in {O}
  Eigen::Vector2d size_m = Eigen::Vector2d::Zero();    // board edges along x_O, y_O, metres
  Eigen::Vector2d min_O() const { return centre_O - 0.5 * size_m; }
  Eigen::Vector2d max_O() const { return centre_O + 0.5 * size_m; }
  bool Contains(const Eigen::Vector2d& p_O) const {
    return (p_O.array() >= min_O().array()).all() && (p_O.array() <= max_O().array()).all();
  }
};

// The printed squares of the pattern (without the white margin), in {O}: min and max corner.
Eigen::AlignedBox2d PatternExtent_O(const PatternSpec& spec);

// The board around `spec`: board_size_m, or (all zero) the pattern plus one square of white
// margin on each side. Throws uwscan::Error when a given size does not hold the pattern and its
// margin.
BoardGeometry BoardOf(const PatternSpec& spec,
                      const Eigen::Vector2d& board_size_m = Eigen::Vector2d::Zero());

struct TargetRenderOptions {
  int supersampling = 3;       // samples per pixel along each axis (box filter), [1, 16]
  double blur_sigma_px = 0.6;  // optics blur after sampling (Gaussian), pixels, [0, 20]
  double white_level = 200.0;  // white paper, image units of `format`
  double black_level = 20.0;   // black print, and whatever is not the board, image units
  double noise_sigma = 1.5;    // additive Gaussian noise, image units, >= 0
  PixelFormat format = PixelFormat::kMono8;
  std::uint64_t seed = 1;  // noise: same seed, same image, whatever the thread count
  Eigen::Vector2d board_size_m = Eigen::Vector2d::Zero();  // 0: pattern + one square margin

  // Throws uwscan::Error naming the field when a value is unusable.
  void Check() const;
};

// Renders calibration targets for one camera. Building it traces the camera's rays in water
// once (CameraRayTable, within 1e-6 rad of the exact rays); every image afterwards costs one
// table lookup and one ray-plane intersection per sample, spread over OpenMP threads.
class TargetRenderer {
 public:
  // Throws uwscan::Error when the camera is unusable.
  explicit TargetRenderer(const RefractiveCamera& camera);

  // The board at pose T_C_O seen by the camera: per sample (supersampling^2 per pixel, on a
  // sheared grid whose samples all differ in row and column) the camera ray in water meets the
  // board's plane and takes the print's level there (black_level where it misses the board or
  // sees its back); the samples of a pixel are averaged, then blurred, noise added, rounded and
  // clipped to the format's range.
  // StripeFrame::truth_px stays empty. Throws uwscan::Error on unusable options or pattern.
  StripeFrame Render(const PatternSpec& spec, const Eigen::Isometry3d& T_C_O,
                     const TargetRenderOptions& options) const;

  const RefractiveCamera& camera() const { return camera_; }

 private:
  RefractiveCamera camera_;
  CameraRayTable rays_;
};

// One-off convenience: TargetRenderer(camera).Render(...).
StripeFrame RenderPattern(const RefractiveCamera& camera, const PatternSpec& spec,
                          const Eigen::Isometry3d& T_C_O, const TargetRenderOptions& options);

// A laser dot as the camera records it (lights off): black_level everywhere plus a round
// Gaussian of standard deviation sigma_px (beam footprint and optics blur together) whose
// centre is centre_px and whose peak is `amplitude` (image units), integrated over each pixel;
// then noise, rounding and clipping as in Render (supersampling and blur_sigma_px unused: the
// Gaussian is integrated exactly and already includes the blur). Throws uwscan::Error on bad
// arguments.
StripeFrame RenderDot(int width_px, int height_px, const Eigen::Vector2d& centre_px,
                      double sigma_px, double amplitude, const TargetRenderOptions& options);

}  // namespace uwscan::scanner::calibration
