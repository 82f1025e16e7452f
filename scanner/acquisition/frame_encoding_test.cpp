#include "scanner/acquisition/frame_encoding.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::acquisition {
namespace {

FrameMetadata SomeMetadata() {
  FrameMetadata m;
  m.frame_counter = 0x0102030405060708ull;
  m.mirror_command = -73;
  m.sweep = 5;
  m.exposure_us = 1234;
  m.timestamp_ns = 987654321012345ull;
  return m;
}

TEST(FrameMetadata, RoundTripsEveryField) {
  std::vector<std::uint8_t> row(100, 0xAB);
  EncodeMetadata(SomeMetadata(), row);
  EXPECT_TRUE(
      std::all_of(row.begin() + kMetadataBytes, row.end(), [](std::uint8_t b) { return b == 0; }));
  const std::optional<FrameMetadata> back = DecodeMetadata(row);
  ASSERT_TRUE(back);
  EXPECT_EQ(*back, SomeMetadata());
}

TEST(FrameMetadata, DamagedOrShortRowsDoNotDecode) {
  std::vector<std::uint8_t> row(kMetadataBytes);
  EncodeMetadata(SomeMetadata(), row);
  for (std::size_t i = 0; i < kMetadataBytes; ++i) {
    std::vector<std::uint8_t> damaged = row;
    damaged[i] ^= 0x10;
    EXPECT_FALSE(DecodeMetadata(damaged)) << "byte " << i;
  }
  EXPECT_FALSE(DecodeMetadata(std::span<const std::uint8_t>(row).first(kMetadataBytes - 1)));
  std::vector<std::uint8_t> zeros(kMetadataBytes, 0);  // a frame whose packets never came
  EXPECT_FALSE(DecodeMetadata(zeros));
  std::vector<std::uint8_t> too_short(10);
  EXPECT_THROW(EncodeMetadata(SomeMetadata(), too_short), Error);
}

TEST(ProfileLayout, FractionBitsFitTheLine) {
  ProfileLayout layout;
  layout.line_length_px = 1024;
  EXPECT_EQ(layout.fraction_bits(), 6);  // 1/64 px
  layout.line_length_px = 1088;
  EXPECT_EQ(layout.fraction_bits(), 5);
  layout.line_length_px = 2048;
  EXPECT_EQ(layout.fraction_bits(), 5);
  layout.line_length_px = 100;
  EXPECT_EQ(layout.fraction_bits(), 8);
  layout.lines = 10;
  EXPECT_THROW(layout.Check(), Error);
}

// Random peaks on random rows, up to 3 per row, everywhere on the line including both ends:
// each comes back within half a fixed-point step (one step at the ends), none is lost.
TEST(ProfileEncoding, RoundTripWithinTheFixedPointStep) {
  for (const StripeAxis axis : {StripeAxis::kRows, StripeAxis::kColumns}) {
    ProfileLayout layout;
    layout.axis = axis;
    layout.lines = axis == StripeAxis::kRows ? 1088 : 2048;
    layout.line_length_px = axis == StripeAxis::kRows ? 2048 : 1088;
    layout.peak_rows = 3;
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> position(-0.5, layout.line_length_px - 0.5);
    std::vector<Eigen::Vector2d> peaks;
    for (int l = 0; l < layout.lines; l += 3) {
      const int n = l % 4;  // 0..3 peaks on this line
      for (int k = 0; k < n; ++k) {
        const double p = l == 0 ? -0.5 : (l == 3 ? layout.line_length_px - 0.5 : position(rng));
        peaks.push_back(axis == StripeAxis::kRows ? Eigen::Vector2d(p, l) : Eigen::Vector2d(l, p));
      }
    }
    std::vector<std::uint8_t> payload(layout.payload_bytes());
    const ProfileEncodeResult encoded = EncodeProfile(layout, peaks, SomeMetadata(), payload);
    EXPECT_EQ(encoded.peaks_encoded, static_cast<int>(peaks.size()));
    EXPECT_EQ(encoded.peaks_dropped, 0);
    const std::optional<DecodedProfile> decoded = DecodeProfile(layout, payload);
    ASSERT_TRUE(decoded);
    EXPECT_EQ(decoded->metadata, SomeMetadata());
    ASSERT_EQ(decoded->peaks_px.size(), peaks.size());
    auto by_line = [axis](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
      return axis == StripeAxis::kRows
                 ? std::make_pair(a.y(), a.x()) < std::make_pair(b.y(), b.x())
                 : std::make_pair(a.x(), a.y()) < std::make_pair(b.x(), b.y());
    };
    std::sort(peaks.begin(), peaks.end(), by_line);
    const double step = std::ldexp(1.0, -layout.fraction_bits());
    for (std::size_t i = 0; i < peaks.size(); ++i) {
      const Eigen::Vector2d d = decoded->peaks_px[i] - peaks[i];
      const double at_line = axis == StripeAxis::kRows ? d.y() : d.x();
      const double along = axis == StripeAxis::kRows ? d.x() : d.y();
      EXPECT_EQ(at_line, 0.0);
      const double p = axis == StripeAxis::kRows ? peaks[i].x() : peaks[i].y();
      const bool end = p < 0.0 || p > layout.line_length_px - 1.0;
      EXPECT_LE(std::abs(along), end ? step : step / 2 + 1e-12) << i;
    }
  }
}

TEST(ProfileEncoding, CountsPeaksBeyondThePeakRowsAndRejectsBadPeaks) {
  ProfileLayout layout;
  layout.lines = 64;
  layout.line_length_px = 100;
  layout.peak_rows = 2;
  std::vector<std::uint8_t> payload(layout.payload_bytes());
  const std::vector<Eigen::Vector2d> three = {{10.25, 5}, {50.5, 5}, {70.0, 5}};
  const ProfileEncodeResult r = EncodeProfile(layout, three, {}, payload);
  EXPECT_EQ(r.peaks_encoded, 2);
  EXPECT_EQ(r.peaks_dropped, 1);
  const std::optional<DecodedProfile> d = DecodeProfile(layout, payload);
  ASSERT_TRUE(d);
  ASSERT_EQ(d->peaks_px.size(), 2u);
  EXPECT_DOUBLE_EQ(d->peaks_px[0].x(), 10.25);
  EXPECT_DOUBLE_EQ(d->peaks_px[1].x(), 50.5);

  const std::vector<Eigen::Vector2d> off_line = {{10.0, 5.5}};
  EXPECT_THROW(EncodeProfile(layout, off_line, {}, payload), Error);
  const std::vector<Eigen::Vector2d> outside = {{100.0, 5}};
  EXPECT_THROW(EncodeProfile(layout, outside, {}, payload), Error);
  const std::vector<Eigen::Vector2d> beyond_lines = {{10.0, 64}};
  EXPECT_THROW(EncodeProfile(layout, beyond_lines, {}, payload), Error);
  std::vector<std::uint8_t> wrong_size(payload.size() + 2);
  EXPECT_THROW(EncodeProfile(layout, three, {}, wrong_size), Error);
  // A payload whose metadata row was lost does not decode.
  std::fill(payload.end() - static_cast<std::ptrdiff_t>(layout.lines * 2), payload.end(), 0);
  EXPECT_FALSE(DecodeProfile(layout, payload));
}

TEST(ImageEncoding, MetadataRowFollowsTheImage) {
  for (const PixelFormat format : {PixelFormat::kMono8, PixelFormat::kMono16}) {
    ImageLayout layout{64, 8, format};
    std::vector<std::uint8_t> payload(layout.payload_bytes(), 7);
    EncodeMetadata(SomeMetadata(),
                   std::span<std::uint8_t>(payload).subspan(layout.row_bytes() * 8));
    const std::optional<DecodedImage> d = DecodeImage(layout, payload);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->metadata, SomeMetadata());
    EXPECT_EQ(d->image.height_px, 8);
    EXPECT_EQ(d->image.format, format);
    EXPECT_EQ(d->image.data, payload.data());
  }
  ImageLayout narrow{16, 8, PixelFormat::kMono8};
  EXPECT_THROW(narrow.Check(), Error);
}

TEST(FrameIdUnwrapper, CountsGapsAcrossTheWrapWhichSkipsZero) {
  FrameIdUnwrapper u;
  EXPECT_EQ(u.Next(65533).frame_number, 0);
  FrameIdUnwrapper::Step s = u.Next(65534);
  EXPECT_EQ(s.frame_number, 1);
  EXPECT_EQ(s.lost_before, 0);
  s = u.Next(1);  // 65535 was lost; 0 does not exist
  EXPECT_EQ(s.frame_number, 3);
  EXPECT_EQ(s.lost_before, 1);
  s = u.Next(2);
  EXPECT_EQ(s.lost_before, 0);
  EXPECT_EQ(s.frame_number, 4);
  s = u.Next(1);  // late
  EXPECT_TRUE(s.stale);
  s = u.Next(2);  // repeated
  EXPECT_TRUE(s.stale);
  s = u.Next(0);  // invalid
  EXPECT_TRUE(s.stale);
  s = u.Next(12);
  EXPECT_EQ(s.frame_number, 14);
  EXPECT_EQ(s.lost_before, 9);
  // Many wraps, every 7th frame lost: the total matches.
  FrameIdUnwrapper v;
  std::int64_t lost = 0;
  std::uint16_t id = 65000;
  v.Next(id);
  for (int n = 1; n < 300000; ++n) {
    id = static_cast<std::uint16_t>(id % 65535 + 1);
    if (n % 7 == 0) continue;
    lost += v.Next(id).lost_before;
  }
  EXPECT_EQ(lost, (300000 - 1) / 7 - ((300000 - 1) % 7 == 0 ? 1 : 0));
}

}  // namespace
}  // namespace uwscan::scanner::acquisition
