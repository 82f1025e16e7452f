#pragma once

#include <filesystem>

#include "scanner/calibration/observations.hpp"
#include "scanner/stripe/stripe_detector.hpp"

namespace uwscan::scanner::calibration {

// The laser stripe of one calibration image: the file is read as it was recorded (8- or 16-bit
// greyscale, any format OpenCV reads) and handed to StripeDetector; the observation keeps the
// image's path (as given) and the mirror step it was taken at. Throws uwscan::Error naming the
// image when it cannot be read or is not single-channel 8- or 16-bit, and on unusable options.
StripeObservation ExtractStripe(const std::filesystem::path& image, int mirror_step,
                                const StripeDetectorOptions& options);

}  // namespace uwscan::scanner::calibration
