#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "scanner/stripe/stripe_detector.hpp"
#include "scanner/stripe/stripe_image.hpp"

// How per-frame data travel inside a GenICam camera's pixels, the way laser-line cameras send
// profiles (in the spirit of GenICam SFNC's Scan3d features): GigE Vision's fake camera sends
// images only, without chunk data, so the peaks, the mirror command and the camera's time of
// each frame ride in the payload itself.
//
// Every payload ends with one metadata row; its first kMetadataBytes bytes (little-endian
// fields, whatever the pixel format) are:
//   0..3  magic "UWSM"        4..5  layout version (1)     6..7 reserved (0)
//   8..15 frame counter (u64, frames the camera took since it started, 0 first)
//   16..19 mirror command (i32: galvo step or MEMS line)    20..23 sweep (i32)
//   24..27 exposure (u32, microseconds)                    28..35 capture time (u64, ns)
//   36..55 reserved (0)       56..63 FNV-1a 64 of bytes 0..55
// The rest of the row is zero. A frame whose packets were lost (Aravis fills nothing in) fails
// the checksum and decodes to std::nullopt.
//
// Profile mode (Mono16, width = number of image lines, height = peak_rows + 1): row k, column l
// holds the k-th peak (in increasing position) along image line l in unsigned fixed point,
// value = round((position_px + 1/2) * 2^fraction_bits), 0 = no peak. fraction_bits is the
// largest b <= 8 with line_length_px * 2^b <= 65536 (1/64 px for lines up to 1024 px, 1/32 up
// to 2048 px), so every position on the line fits; a decoded position is within half a step
// (2^-fraction_bits / 2 px) of the encoded one, one step at the two ends of the line.
//
// Image mode: the sensor's rows, then the metadata row (height = sensor height + 1).
namespace uwscan::scanner::acquisition {

inline constexpr std::size_t kMetadataBytes = 64;

struct FrameMetadata {
  std::uint64_t frame_counter = 0;  // frames the camera took since it started, 0 first
  std::int32_t mirror_command = 0;  // galvo: mirror step; MEMS: line index in the scan pattern
  std::int32_t sweep = 0;           // which sweep of the scan pattern
  std::uint32_t exposure_us = 0;    // exposure time, microseconds
  std::uint64_t timestamp_ns = 0;   // capture time on the camera's clock, nanoseconds

  bool operator==(const FrameMetadata&) const = default;
};

// Writes the metadata into the first kMetadataBytes of `row` and zeroes the rest. Throws
// uwscan::Error when the row is shorter than kMetadataBytes.
void EncodeMetadata(const FrameMetadata& metadata, std::span<std::uint8_t> row);
// std::nullopt when the row is too short or its magic, version or checksum do not match.
std::optional<FrameMetadata> DecodeMetadata(std::span<const std::uint8_t> row);

// The shape of a profile-mode payload.
struct ProfileLayout {
  int lines = 1088;           // image lines searched (rows for kRows): the payload's width
  int line_length_px = 2048;  // pixels along one line (the image width for kRows)
  int peak_rows = 4;          // peaks carried per line, in [1, 64]
  StripeAxis axis = StripeAxis::kRows;

  // Throws uwscan::Error naming the field when a value is out of range.
  void Check() const;
  int fraction_bits() const;
  int payload_width_px() const { return lines; }
  int payload_height_px() const { return peak_rows + 1; }
  std::size_t payload_bytes() const {
    return static_cast<std::size_t>(lines) * static_cast<std::size_t>(peak_rows + 1) * 2;
  }
};

struct ProfileEncodeResult {
  int peaks_encoded = 0;
  int peaks_dropped = 0;  // beyond peak_rows on their line
};

// Encodes `peaks_px` ((u, v) pixels; for kRows v is the row, an integer, and u the position)
// and `metadata` into `payload` (layout.payload_bytes() bytes, Mono16, native = little endian).
// Throws uwscan::Error when the payload size is wrong, or a peak is not finite, not on a line
// centre (more than 1e-6 px off) or outside the image.
ProfileEncodeResult EncodeProfile(const ProfileLayout& layout,
                                  std::span<const Eigen::Vector2d> peaks_px,
                                  const FrameMetadata& metadata, std::span<std::uint8_t> payload);

struct DecodedProfile {
  FrameMetadata metadata;
  std::vector<Eigen::Vector2d> peaks_px;  // line by line, increasing position within a line
};

// std::nullopt when the payload is too short or its metadata row does not decode.
std::optional<DecodedProfile> DecodeProfile(const ProfileLayout& layout,
                                            std::span<const std::uint8_t> payload);

// The shape of an image-mode payload: the sensor's rows, then the metadata row.
struct ImageLayout {
  int width_px = 2048;
  int height_px = 1088;  // sensor rows, without the metadata row
  PixelFormat format = PixelFormat::kMono8;

  void Check() const;  // throws uwscan::Error: a row must hold kMetadataBytes
  int payload_height_px() const { return height_px + 1; }
  std::size_t row_bytes() const {
    return static_cast<std::size_t>(width_px) * static_cast<std::size_t>(BytesPerPixel(format));
  }
  std::size_t payload_bytes() const {
    return row_bytes() * static_cast<std::size_t>(height_px + 1);
  }
};

// The image part of an image-mode payload (a view into it) and its metadata.
struct DecodedImage {
  FrameMetadata metadata;
  StripeImage image;
};
std::optional<DecodedImage> DecodeImage(const ImageLayout& layout,
                                        std::span<const std::uint8_t> payload);

// GigE Vision's 16-bit frame (block) ids count 1..65535 and wrap to 1 (0 is invalid). This
// unwraps them into a 64-bit frame number and counts the ids that never arrived. A frame whose
// id lies behind the last one (more than half the id range ahead) is late or repeated: it is
// reported as stale and changes nothing.
class FrameIdUnwrapper {
 public:
  struct Step {
    std::int64_t frame_number = 0;  // 0 for the first id seen, then +1 per id
    std::int64_t lost_before = 0;   // ids skipped since the previous frame
    bool stale = false;
  };
  Step Next(std::uint16_t id);
  // Forget the last id (a camera that was reopened starts a new count).
  void Reset() { started_ = false; }

 private:
  bool started_ = false;
  std::uint16_t last_id_ = 0;
  std::int64_t last_number_ = 0;
};

}  // namespace uwscan::scanner::acquisition
