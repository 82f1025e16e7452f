#include "ros/conversions/dive_description.hpp"

#include <gtest/gtest.h>

#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::ros {
namespace {

TEST(DiveDescription, RoundTripsTheScannerPatternNoiseAndOrigin) {
  DiveDescription d;
  d.header.scanner = scanner::DefaultScanner(scanner::ScannerKind::kGalvo);
  d.header.scan_pattern.kind = scanner::ScannerKind::kGalvo;
  d.header.producer = "test";
  d.header.navigation_noise = mapping::NavigationNoise{0.003, 0.0005, 0.01, 0.02, 0.001, 0.0005};
  d.time_origin_s = 1733097600.0;
  const DiveDescription back = ParseDiveDescription(DiveDescriptionToYaml(d), "topic /uwscan/dive");
  EXPECT_EQ(back.time_origin_s, d.time_origin_s);
  EXPECT_EQ(back.header.producer, "test");
  EXPECT_EQ(scanner::ScannerToYaml(back.header.scanner), scanner::ScannerToYaml(d.header.scanner));
  EXPECT_EQ(scanner::ScanPatternToYaml(back.header.scan_pattern),
            scanner::ScanPatternToYaml(d.header.scan_pattern));
  ASSERT_TRUE(back.header.navigation_noise);
  EXPECT_EQ(back.header.navigation_noise->heading_bias_sigma_rad, 0.02);
  EXPECT_EQ(back.header.navigation_noise->depth_sigma_m, 0.001);
}

TEST(DiveDescription, MalformedTextNamesTheSourceAndField) {
  const auto message = [](const std::string& text) {
    try {
      ParseDiveDescription(text, "topic /d");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("parsed");
  };
  EXPECT_NE(message("[1, 2").find("topic /d"), std::string::npos);
  EXPECT_NE(message("uwscan_format: 2\n").find("format 2"), std::string::npos);
  EXPECT_NE(message("uwscan_format: 1\n").find("time_origin_s"), std::string::npos);
  EXPECT_NE(message("uwscan_format: 1\ntime_origin_s: -1\n").find("time_origin_s"),
            std::string::npos);
  EXPECT_NE(message("uwscan_format: 1\ntime_origin_s: 0\n").find("scanner"), std::string::npos);
}

}  // namespace
}  // namespace uwscan::ros
