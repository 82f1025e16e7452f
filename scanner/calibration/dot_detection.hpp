#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>

namespace uwscan::scanner::calibration {

struct DotDetectionOptions {
  // A dot is the brightest blob: pixels above background + threshold_fraction x (peak -
  // background), the background being the image's median.
  double threshold_fraction = 0.3;
  int min_peak_above_background = 20;  // image units (Mono8 scale; Mono16 is scaled to it)
  int max_radius_px = 40;              // a larger blob is not a laser dot
  void Check() const;
};

// The laser dot of a MEMS calibration image: the intensity-weighted centroid (background
// removed) of the connected bright blob around the brightest pixel, sub-pixel. A blob centroid
// rather than a circle Hough transform: the dot is a small Gaussian spot whose centroid is
// unbiased, while Hough circles quantise its centre and need a visible rim. std::nullopt when
// no dot stands out or the blob touches the image border or exceeds max_radius_px; uwscan::Error
// naming the file when the image cannot be read or is not single-channel.
std::optional<Eigen::Vector2d> DetectDot(const std::filesystem::path& image,
                                         const DotDetectionOptions& options = {});

}  // namespace uwscan::scanner::calibration
