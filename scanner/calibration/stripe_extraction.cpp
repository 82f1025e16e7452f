#include "scanner/calibration/stripe_extraction.hpp"

#include <opencv2/imgcodecs.hpp>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::calibration {

StripeObservation ExtractStripe(const std::filesystem::path& image, int mirror_step,
                                const StripeDetectorOptions& options) {
  options.Check();
  // IMREAD_UNCHANGED keeps 16-bit frames 16-bit and refuses to invent a greyscale from colour.
  const cv::Mat pixels = cv::imread(image.string(), cv::IMREAD_UNCHANGED);
  if (pixels.empty()) {
    throw Error(image.string() + ": cannot read the stripe image (missing, or not an image)");
  }
  if (pixels.channels() != 1 || (pixels.depth() != CV_8U && pixels.depth() != CV_16U)) {
    throw Error(image.string() + ": stripe image has " + std::to_string(pixels.channels()) +
                " channel(s) of " +
                (pixels.depth() == CV_8U || pixels.depth() == CV_16U
                     ? std::to_string(pixels.elemSize1() * 8) + " bits"
                     : std::string("a non-integer or signed type")) +
                ", expected one channel of 8 or 16 bits (Mono8, Mono16)");
  }
  const StripeImage view =
      pixels.depth() == CV_8U
          ? StripeImage::Mono8(pixels.ptr<std::uint8_t>(), pixels.cols, pixels.rows,
                               static_cast<std::ptrdiff_t>(pixels.step[0]))
          : StripeImage::Mono16(pixels.ptr<std::uint16_t>(), pixels.cols, pixels.rows,
                                static_cast<std::ptrdiff_t>(pixels.step[0]));
  StripeDetector detector(options);
  const StripeDetection detection = detector.Detect(view);
  StripeObservation observation;
  observation.image = image.string();
  observation.mirror_step = mirror_step;
  observation.peaks_px.reserve(detection.peaks.size());
  for (const StripePeak& peak : detection.peaks)
    observation.peaks_px.emplace_back(peak.u_px, peak.v_px);
  return observation;
}

}  // namespace uwscan::scanner::calibration
