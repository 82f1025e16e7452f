#include "scanner/acquisition/frame_encoding.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/common/fnv1a.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner::acquisition {
namespace {

constexpr std::uint8_t kMagic[4] = {'U', 'W', 'S', 'M'};
constexpr std::uint16_t kLayoutVersion = 1;
constexpr std::size_t kChecksumOffset = 56;

template <typename T>
void Put(std::uint8_t* at, T value) {
  using U = std::make_unsigned_t<T>;
  U u = static_cast<U>(value);
  for (std::size_t i = 0; i < sizeof(T); ++i)
    at[i] = static_cast<std::uint8_t>((u >> (8 * i)) & 0xFF);
}

template <typename T>
T Get(const std::uint8_t* at) {
  using U = std::make_unsigned_t<T>;
  U u = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i) u |= static_cast<U>(static_cast<U>(at[i]) << (8 * i));
  return static_cast<T>(u);
}

std::uint64_t Checksum(const std::uint8_t* row) {
  return Fnv1a64(reinterpret_cast<const char*>(row), kChecksumOffset);
}

// Pixels of row k of a Mono16 payload of `width` pixels (native = little endian on every
// platform uwscan builds for; GigE Vision's Mono16 is little endian).
const std::uint16_t* Row16(std::span<const std::uint8_t> payload, int width, int k) {
  return reinterpret_cast<const std::uint16_t*>(payload.data() +
                                                static_cast<std::size_t>(k) * width * 2);
}

}  // namespace

void EncodeMetadata(const FrameMetadata& m, std::span<std::uint8_t> row) {
  if (row.size() < kMetadataBytes) {
    throw Error("frame metadata: row of " + std::to_string(row.size()) +
                " bytes, expected at least " + std::to_string(kMetadataBytes));
  }
  std::fill(row.begin(), row.end(), std::uint8_t{0});
  std::uint8_t* p = row.data();
  std::memcpy(p, kMagic, 4);
  Put<std::uint16_t>(p + 4, kLayoutVersion);
  Put<std::uint64_t>(p + 8, m.frame_counter);
  Put<std::int32_t>(p + 16, m.mirror_command);
  Put<std::int32_t>(p + 20, m.sweep);
  Put<std::uint32_t>(p + 24, m.exposure_us);
  Put<std::uint64_t>(p + 28, m.timestamp_ns);
  Put<std::uint64_t>(p + kChecksumOffset, Checksum(p));
}

std::optional<FrameMetadata> DecodeMetadata(std::span<const std::uint8_t> row) {
  if (row.size() < kMetadataBytes) return std::nullopt;
  const std::uint8_t* p = row.data();
  if (std::memcmp(p, kMagic, 4) != 0 || Get<std::uint16_t>(p + 4) != kLayoutVersion)
    return std::nullopt;
  if (Get<std::uint64_t>(p + kChecksumOffset) != Checksum(p)) return std::nullopt;
  FrameMetadata m;
  m.frame_counter = Get<std::uint64_t>(p + 8);
  m.mirror_command = Get<std::int32_t>(p + 16);
  m.sweep = Get<std::int32_t>(p + 20);
  m.exposure_us = Get<std::uint32_t>(p + 24);
  m.timestamp_ns = Get<std::uint64_t>(p + 28);
  return m;
}

void ProfileLayout::Check() const {
  const OptionChecks check("ProfileLayout");
  check.InRange("lines", lines, 32, 65535, Interval::kClosed, "(the metadata row needs 32 pixels)");
  check.InRange("line_length_px", line_length_px, 1, 65536, Interval::kClosed, "px");
  check.InRange("peak_rows", peak_rows, 1, 64);
}

int ProfileLayout::fraction_bits() const {
  int bits = 8;
  while (bits > 0 && static_cast<std::int64_t>(line_length_px) << bits > 65536) --bits;
  return bits;
}

ProfileEncodeResult EncodeProfile(const ProfileLayout& layout,
                                  std::span<const Eigen::Vector2d> peaks_px,
                                  const FrameMetadata& metadata, std::span<std::uint8_t> payload) {
  layout.Check();
  if (payload.size() != layout.payload_bytes()) {
    throw Error("profile encoding: payload of " + std::to_string(payload.size()) +
                " bytes, expected " + std::to_string(layout.payload_bytes()));
  }
  const bool rows = layout.axis == StripeAxis::kRows;
  const double scale = std::ldexp(1.0, layout.fraction_bits());
  // Positions per line, sorted, then written peak row by peak row.
  std::vector<std::vector<double>> per_line(static_cast<std::size_t>(layout.lines));
  for (const Eigen::Vector2d& p : peaks_px) {
    if (!p.allFinite()) throw Error("profile encoding: a peak is not finite");
    const double line_coord = rows ? p.y() : p.x();
    const double position = rows ? p.x() : p.y();
    const double line = std::round(line_coord);
    if (std::abs(line_coord - line) > 1e-6) {
      throw Error("profile encoding: peak (" + std::to_string(p.x()) + ", " +
                  std::to_string(p.y()) + ") px is not on a line centre");
    }
    if (line < 0 || line >= layout.lines || position < -0.5 ||
        position > layout.line_length_px - 0.5) {
      throw Error("profile encoding: peak (" + std::to_string(p.x()) + ", " +
                  std::to_string(p.y()) + ") px lies outside the image");
    }
    per_line[static_cast<std::size_t>(line)].push_back(position);
  }
  ProfileEncodeResult result;
  std::fill(payload.begin(), payload.end(), std::uint8_t{0});
  auto* pixels = reinterpret_cast<std::uint16_t*>(payload.data());
  for (int l = 0; l < layout.lines; ++l) {
    std::vector<double>& positions = per_line[static_cast<std::size_t>(l)];
    std::sort(positions.begin(), positions.end());
    const int n = static_cast<int>(positions.size());
    for (int k = 0; k < n; ++k) {
      if (k >= layout.peak_rows) {
        ++result.peaks_dropped;
        continue;
      }
      const double value = std::round((positions[static_cast<std::size_t>(k)] + 0.5) * scale);
      pixels[static_cast<std::size_t>(k) * layout.lines + l] =
          static_cast<std::uint16_t>(std::clamp(value, 1.0, 65535.0));
      ++result.peaks_encoded;
    }
  }
  EncodeMetadata(metadata,
                 payload.subspan(static_cast<std::size_t>(layout.peak_rows) * layout.lines * 2));
  return result;
}

std::optional<DecodedProfile> DecodeProfile(const ProfileLayout& layout,
                                            std::span<const std::uint8_t> payload) {
  layout.Check();
  if (payload.size() < layout.payload_bytes()) return std::nullopt;
  const std::size_t row_bytes = static_cast<std::size_t>(layout.lines) * 2;
  std::optional<FrameMetadata> metadata = DecodeMetadata(
      payload.subspan(static_cast<std::size_t>(layout.peak_rows) * row_bytes, row_bytes));
  if (!metadata) return std::nullopt;
  DecodedProfile out;
  out.metadata = *metadata;
  const double step = std::ldexp(1.0, -layout.fraction_bits());
  const bool rows = layout.axis == StripeAxis::kRows;
  for (int l = 0; l < layout.lines; ++l) {
    for (int k = 0; k < layout.peak_rows; ++k) {
      const std::uint16_t value = Row16(payload, layout.lines, k)[l];
      if (value == 0) break;
      const double position = value * step - 0.5;
      out.peaks_px.emplace_back(rows ? position : l, rows ? l : position);
    }
  }
  return out;
}

void ImageLayout::Check() const {
  const OptionChecks check("ImageLayout");
  check.InRange("width_px", width_px, 1, 65535, Interval::kClosed, "px");
  check.InRange("height_px", height_px, 1, 65534, Interval::kClosed, "px");
  check.Require(row_bytes() >= kMetadataBytes, "width_px",
                "a row of at least " + std::to_string(kMetadataBytes) + " bytes (the metadata row)",
                std::to_string(row_bytes()) + " bytes");
}

std::optional<DecodedImage> DecodeImage(const ImageLayout& layout,
                                        std::span<const std::uint8_t> payload) {
  layout.Check();
  if (payload.size() < layout.payload_bytes()) return std::nullopt;
  std::optional<FrameMetadata> metadata = DecodeMetadata(payload.subspan(
      layout.row_bytes() * static_cast<std::size_t>(layout.height_px), layout.row_bytes()));
  if (!metadata) return std::nullopt;
  DecodedImage out;
  out.metadata = *metadata;
  out.image.data = payload.data();
  out.image.width_px = layout.width_px;
  out.image.height_px = layout.height_px;
  out.image.stride_bytes = static_cast<std::ptrdiff_t>(layout.row_bytes());
  out.image.format = layout.format;
  return out;
}

FrameIdUnwrapper::Step FrameIdUnwrapper::Next(std::uint16_t id) {
  Step step;
  if (id == 0) {  // invalid in GigE Vision
    step.stale = true;
    step.frame_number = last_number_;
    return step;
  }
  if (!started_) {
    started_ = true;
    last_id_ = id;
    last_number_ = 0;
    return step;
  }
  // Ids live in 1..65535: distances are taken modulo 65535.
  const int distance = (static_cast<int>(id) - static_cast<int>(last_id_) + 65535) % 65535;
  if (distance == 0 || distance > 32767) {
    step.stale = true;
    step.frame_number = last_number_;
    return step;
  }
  last_id_ = id;
  last_number_ += distance;
  step.frame_number = last_number_;
  step.lost_before = distance - 1;
  return step;
}

}  // namespace uwscan::scanner::acquisition
