#include "scanner/calibration/dot_detection.hpp"

#include <algorithm>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner::calibration {
namespace {

double Median(const cv::Mat& image) {
  std::vector<float> values;
  values.reserve(image.total());
  for (int v = 0; v < image.rows; ++v) {
    const float* row = image.ptr<float>(v);
    values.insert(values.end(), row, row + image.cols);
  }
  auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

void DotDetectionOptions::Check() const {
  const OptionChecks check("DotDetectionOptions");
  check.InRange("threshold_fraction", threshold_fraction, 0.0, 1.0, Interval::kOpen);
  check.AtLeast("min_peak_above_background", min_peak_above_background, 1, "image units");
  check.AtLeast("max_radius_px", max_radius_px, 1, "px");
}

std::optional<Eigen::Vector2d> DetectDot(const std::filesystem::path& image_path,
                                         const DotDetectionOptions& options) {
  options.Check();
  const cv::Mat raw = cv::imread(image_path.string(), cv::IMREAD_UNCHANGED);
  if (raw.empty()) throw Error(image_path.string() + ": cannot read the image");
  if (raw.channels() != 1 || (raw.depth() != CV_8U && raw.depth() != CV_16U)) {
    throw Error(image_path.string() + ": expected a Mono8 or Mono16 image");
  }
  cv::Mat image;
  raw.convertTo(image, CV_32F, raw.depth() == CV_16U ? 255.0 / 65535.0 : 1.0);

  const double background = Median(image);
  double peak = 0.0;
  cv::Point at;
  cv::minMaxLoc(image, nullptr, &peak, nullptr, &at);
  if (peak - background < options.min_peak_above_background) return std::nullopt;
  const float threshold =
      static_cast<float>(background + options.threshold_fraction * (peak - background));

  // Flood the blob from the brightest pixel (4-connected), summing background-free intensity.
  cv::Mat visited(image.size(), CV_8U, cv::Scalar(0));
  std::vector<cv::Point> stack = {at};
  visited.at<std::uint8_t>(at) = 1;
  double sum = 0.0, su = 0.0, sv = 0.0;
  const int r2_max = options.max_radius_px * options.max_radius_px;
  while (!stack.empty()) {
    const cv::Point p = stack.back();
    stack.pop_back();
    if (p.x == 0 || p.y == 0 || p.x == image.cols - 1 || p.y == image.rows - 1) return std::nullopt;
    if ((p.x - at.x) * (p.x - at.x) + (p.y - at.y) * (p.y - at.y) > r2_max) return std::nullopt;
    const double w = image.at<float>(p) - background;
    sum += w;
    su += w * p.x;
    sv += w * p.y;
    for (const cv::Point d :
         {cv::Point(1, 0), cv::Point(-1, 0), cv::Point(0, 1), cv::Point(0, -1)}) {
      const cv::Point q = p + d;
      if (visited.at<std::uint8_t>(q) || image.at<float>(q) < threshold) continue;
      visited.at<std::uint8_t>(q) = 1;
      stack.push_back(q);
    }
  }
  if (!(sum > 0.0)) return std::nullopt;
  return Eigen::Vector2d(su / sum, sv / sum);
}

}  // namespace uwscan::scanner::calibration
