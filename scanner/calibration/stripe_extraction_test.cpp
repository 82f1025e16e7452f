#include "scanner/calibration/stripe_extraction.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "scanner/common/error.hpp"
#include "scanner/stripe/stripe_render.hpp"

namespace uwscan::scanner::calibration {
namespace {

namespace fs = std::filesystem;

// This process's scratch folder, removed when the test program ends.
fs::path TestFolder() {
  fs::path folder =
      fs::temp_directory_path() / ("uwscan_stripe_extraction_test_" + std::to_string(getpid()));
  fs::create_directories(folder);
  return folder;
}
struct RemoveScratch : ::testing::Environment {
  void TearDown() override { fs::remove_all(TestFolder()); }
};
[[maybe_unused]] const ::testing::Environment* const kRemoveScratch =
    ::testing::AddGlobalTestEnvironment(new RemoveScratch);

// A clean near-vertical stripe written as PNG, read back through ExtractStripe: the detector
// sees exactly the pixels that were rendered, whatever the bit depth.
void CheckRoundTrip(PixelFormat format, const std::string& name) {
  StripeRenderOptions render;
  render.width_px = 320;
  render.height_px = 200;
  render.format = format;
  render.axis = StripeAxis::kRows;
  StripeSpec stripe;
  stripe.centre.offset_px = 150.3;
  stripe.amplitude = format == PixelFormat::kMono8 ? 200.0 : 50000.0;
  const StripeFrame frame = RenderStripes(render, {stripe});
  const bool mono8 = format == PixelFormat::kMono8;
  const cv::Mat pixels(frame.height_px, frame.width_px, mono8 ? CV_8UC1 : CV_16UC1,
                       mono8 ? static_cast<void*>(const_cast<std::uint8_t*>(frame.mono8.data()))
                             : static_cast<void*>(const_cast<std::uint16_t*>(frame.mono16.data())));
  const fs::path path = TestFolder() / name;
  ASSERT_TRUE(cv::imwrite(path.string(), pixels));

  StripeDetectorOptions options;
  options.axis = StripeAxis::kRows;
  options.threshold = mono8 ? 40 : 10000;
  const StripeObservation observation = ExtractStripe(path, -42, options);
  EXPECT_EQ(observation.image, path.string());
  EXPECT_EQ(observation.mirror_step, -42);
  // Every row but the ones the Steger support cannot cover carries a peak.
  ASSERT_GT(observation.peaks_px.size(), 180u);
  double worst = 0.0;
  for (const Eigen::Vector2d& peak : observation.peaks_px) {
    const double truth = frame.truth_px[static_cast<size_t>(std::lround(peak.y()))];
    worst = std::max(worst, std::abs(peak.x() - truth));
  }
  EXPECT_LT(worst, 0.05) << name;
}

TEST(StripeExtraction, Mono8PngGivesTheRenderedStripe) {
  CheckRoundTrip(PixelFormat::kMono8, "s8.png");
}

TEST(StripeExtraction, Mono16PngGivesTheRenderedStripe) {
  CheckRoundTrip(PixelFormat::kMono16, "s16.png");
}

TEST(StripeExtraction, UnreadableOrColourImagesAreNamed) {
  const fs::path folder = TestFolder();
  StripeDetectorOptions options;
  try {
    ExtractStripe(folder / "missing.png", 0, options);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing.png: cannot read the stripe image"),
              std::string::npos)
        << e.what();
  }
  ASSERT_TRUE(
      cv::imwrite((folder / "colour.png").string(), cv::Mat(20, 30, CV_8UC3, cv::Scalar(1, 2, 3))));
  try {
    ExtractStripe(folder / "colour.png", 0, options);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("colour.png: stripe image has 3 channel(s)"),
              std::string::npos)
        << e.what();
  }
  ASSERT_TRUE(
      cv::imwrite((folder / "float.tiff").string(), cv::Mat(20, 30, CV_32FC1, cv::Scalar(0.5))));
  EXPECT_THROW(ExtractStripe(folder / "float.tiff", 0, options), Error);
  std::ofstream(folder / "text.png") << "not an image";
  EXPECT_THROW(ExtractStripe(folder / "text.png", 0, options), Error);
  options.threshold = 0;
  EXPECT_THROW(ExtractStripe(folder / "colour.png", 0, options), Error);  // options first
}

}  // namespace
}  // namespace uwscan::scanner::calibration
