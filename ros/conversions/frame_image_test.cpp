#include "ros/conversions/frame_image.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

scanner::PinholeCamera Camera(int width, int height) {
  scanner::PinholeCamera c;
  c.width_px = width;
  c.height_px = height;
  c.fx_px = c.fy_px = 1000.0;
  c.cx_px = width / 2.0;
  c.cy_px = height / 2.0;
  return c;
}

// A frame of a near-vertical stripe: one peak per row (two on a few rows), u sub-pixel.
mapping::FrameRecord RowFrame(int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, width - 1.0);
  mapping::FrameRecord f;
  f.index = 7;
  f.time_s = 12.3456789;
  f.command = -42;
  f.sweep = 3;
  for (int v = 0; v < height; v += 3) {
    const double first = u(rng);
    f.peaks_px.emplace_back(first, v);
    if (v % 30 == 0) {
      const double second = u(rng);
      f.peaks_px.emplace_back(second, v);
    }
  }
  return f;
}

TEST(FrameImage, ProfileCarriesEveryPeakWithinHalfAStep) {
  const scanner::PinholeCamera camera = Camera(640, 480);
  const mapping::FrameRecord frame = RowFrame(640, 480, 1);
  ProfileLayoutFinder finder;
  finder.Add(frame);
  const scanner::acquisition::ProfileLayout layout = finder.Layout(camera);
  EXPECT_EQ(layout.axis, scanner::StripeAxis::kRows);
  EXPECT_EQ(layout.lines, 480);
  EXPECT_EQ(layout.peak_rows, 2);
  const ImageMessage image =
      FrameToImage(frame, layout, 99, Header{1000.0 + frame.time_s, "camera"});
  EXPECT_EQ(image.encoding, "mono16");
  EXPECT_EQ(image.width, 480u);
  EXPECT_EQ(image.height, 3u);

  FrameImageDecoder decoder(camera, {}, false);
  const std::optional<mapping::FrameRecord> back = decoder.Decode(image, frame.time_s, "/frames");
  ASSERT_TRUE(back);
  EXPECT_EQ(back->command, frame.command);
  EXPECT_EQ(back->sweep, frame.sweep);
  EXPECT_EQ(back->time_s, frame.time_s);
  ASSERT_EQ(back->peaks_px.size(), frame.peaks_px.size());
  // Decoded line by line in increasing u: match each original peak to a decoded one on its row.
  const double half_step = 0.5 / (1 << layout.fraction_bits());
  for (const Eigen::Vector2d& p : frame.peaks_px) {
    double best = 1e9;
    for (const Eigen::Vector2d& q : back->peaks_px) {
      if (q.y() == p.y()) best = std::min(best, std::abs(q.x() - p.x()));
    }
    EXPECT_LE(best, half_step + 1e-12) << "peak at row " << p.y();
  }
}

TEST(FrameImage, ColumnsAreFoundFromWholeUAndImagesTravelWhole) {
  const scanner::PinholeCamera camera = Camera(320, 200);
  mapping::FrameRecord columns;
  for (int u = 0; u < 320; u += 5) columns.peaks_px.emplace_back(u, 10.25 + u * 0.1);
  ProfileLayoutFinder finder;
  finder.Add(columns);
  EXPECT_EQ(finder.Layout(camera).axis, scanner::StripeAxis::kColumns);
  EXPECT_EQ(finder.Layout(camera).lines, 320);

  mapping::FrameRecord with_image;
  with_image.command = 5;
  with_image.image = mapping::LogImage{320, 200, mapping::LogPixelFormat::kMono8,
                                       std::vector<std::uint8_t>(320 * 200)};
  for (int v = 0; v < 200; ++v)
    with_image.image->bytes[static_cast<std::size_t>(v * 320 + 100)] = 250;
  const ImageMessage image =
      FrameToImage(with_image, finder.Layout(camera), 0, Header{5.0, "camera"});
  EXPECT_EQ(image.encoding, "mono8");
  EXPECT_EQ(image.height, 201u);
  FrameImageDecoder decoder(camera, {}, true);
  const std::optional<mapping::FrameRecord> back = decoder.Decode(image, 5.0, "/frames");
  ASSERT_TRUE(back);
  ASSERT_TRUE(back->image);
  EXPECT_EQ(back->image->bytes, with_image.image->bytes);
  EXPECT_EQ(back->command, 5);
}

TEST(FrameImage, PeaksOffEveryLineGridAreRefused) {
  mapping::FrameRecord f;
  f.peaks_px = {{10.5, 20.5}};
  ProfileLayoutFinder finder;
  finder.Add(f);
  EXPECT_THROW(finder.Layout(Camera(64, 64)), Error);
}

TEST(FrameImage, WrongEncodingSizeOrDamageAreNamed) {
  const scanner::PinholeCamera camera = Camera(640, 480);
  FrameImageDecoder decoder(camera, {}, false);
  ImageMessage m;
  m.encoding = "rgb8";
  m.width = 480;
  m.height = 3;
  m.step = 480 * 3;
  m.data.resize(m.step * 3);
  try {
    decoder.Decode(m, 0.0, "/cam/profile");
    FAIL() << "an rgb8 image was decoded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/cam/profile"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("rgb8"), std::string::npos) << e.what();
  }
  m.encoding = "mono16";
  m.width = 100;  // neither 480 lines nor 640 columns
  m.step = 200;
  m.data.resize(600);
  EXPECT_THROW(decoder.Decode(m, 0.0, "/cam/profile"), Error);

  const mapping::FrameRecord frame = RowFrame(640, 480, 2);
  ProfileLayoutFinder finder;
  finder.Add(frame);
  ImageMessage good = FrameToImage(frame, finder.Layout(camera), 0, Header{});
  good.data[good.data.size() - good.step + 10] ^= 0x01;  // inside the metadata row's checked bytes
  EXPECT_FALSE(decoder.Decode(good, 0.0, "/cam/profile"));
}

}  // namespace
}  // namespace uwscan::ros
