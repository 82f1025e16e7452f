#include "ros/conversions/frame_image.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace acq = scanner::acquisition;
namespace {

bool OnLineCentre(double x) { return std::abs(x - std::round(x)) <= 1e-6; }

// The most peaks on one line of the frame, lines along `axis`.
int BusiestLine(const mapping::FrameRecord& frame, scanner::StripeAxis axis) {
  std::map<long, int> per_line;
  int most = 1;
  for (const Eigen::Vector2d& p : frame.peaks_px) {
    const double line = axis == scanner::StripeAxis::kRows ? p.y() : p.x();
    most = std::max(most, ++per_line[std::lround(line)]);
  }
  return most;
}

std::string SizeText(std::uint32_t width, std::uint32_t height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

}  // namespace

void ProfileLayoutFinder::Add(const mapping::FrameRecord& frame) {
  for (const Eigen::Vector2d& p : frame.peaks_px) {
    rows_ = rows_ && OnLineCentre(p.y());
    columns_ = columns_ && OnLineCentre(p.x());
  }
  if (rows_) busiest_row_ = std::max(busiest_row_, BusiestLine(frame, scanner::StripeAxis::kRows));
  if (columns_)
    busiest_column_ = std::max(busiest_column_, BusiestLine(frame, scanner::StripeAxis::kColumns));
}

acq::ProfileLayout ProfileLayoutFinder::Layout(const scanner::PinholeCamera& camera) const {
  if (!rows_ && !columns_) {
    throw Error(
        "frames: peaks lie on neither whole rows nor whole columns; a profile cannot carry them");
  }
  acq::ProfileLayout layout;
  layout.axis = rows_ ? scanner::StripeAxis::kRows : scanner::StripeAxis::kColumns;
  layout.lines = rows_ ? camera.height_px : camera.width_px;
  layout.line_length_px = rows_ ? camera.width_px : camera.height_px;
  layout.peak_rows = rows_ ? busiest_row_ : busiest_column_;
  if (layout.peak_rows > 64) {
    throw Error("frames: a line holds " + std::to_string(layout.peak_rows) +
                " peaks, a profile carries at most 64");
  }
  layout.Check();
  return layout;
}

ImageMessage FrameToImage(const mapping::FrameRecord& frame, const acq::ProfileLayout& layout,
                          std::uint64_t counter, const Header& header) {
  acq::FrameMetadata metadata;
  metadata.frame_counter = counter;
  metadata.mirror_command = frame.command;
  metadata.sweep = frame.sweep;
  metadata.timestamp_ns =
      static_cast<std::uint64_t>(std::llround(std::max(0.0, frame.time_s) * 1e9));
  ImageMessage m;
  m.header = header;
  if (frame.image) {
    const mapping::LogImage& image = *frame.image;
    const acq::ImageLayout l{image.width_px, image.height_px,
                             image.format == mapping::LogPixelFormat::kMono8
                                 ? scanner::PixelFormat::kMono8
                                 : scanner::PixelFormat::kMono16};
    l.Check();
    m.width = static_cast<std::uint32_t>(l.width_px);
    m.height = static_cast<std::uint32_t>(l.payload_height_px());
    m.step = static_cast<std::uint32_t>(l.row_bytes());
    m.encoding = l.format == scanner::PixelFormat::kMono8 ? "mono8" : "mono16";
    m.data.resize(l.payload_bytes());
    std::copy(image.bytes.begin(), image.bytes.end(), m.data.begin());
    acq::EncodeMetadata(
        metadata, std::span(m.data).subspan(l.row_bytes() * static_cast<std::size_t>(l.height_px)));
    return m;
  }
  m.width = static_cast<std::uint32_t>(layout.payload_width_px());
  m.height = static_cast<std::uint32_t>(layout.payload_height_px());
  m.step = m.width * 2;
  m.encoding = "mono16";
  m.data.resize(layout.payload_bytes());
  const acq::ProfileEncodeResult r = acq::EncodeProfile(layout, frame.peaks_px, metadata, m.data);
  if (r.peaks_dropped > 0) {
    throw Error("frame " + std::to_string(frame.index) + ": " + std::to_string(r.peaks_dropped) +
                " peaks do not fit the profile's " + std::to_string(layout.peak_rows) + " rows");
  }
  return m;
}

FrameImageDecoder::FrameImageDecoder(const scanner::PinholeCamera& camera,
                                     const scanner::StripeDetectorOptions& detector,
                                     bool keep_images)
    : camera_(camera), detector_(detector), keep_images_(keep_images) {}

std::optional<mapping::FrameRecord> FrameImageDecoder::Decode(const ImageMessage& m, double time_s,
                                                              const std::string& topic) {
  const bool mono8 = m.encoding == "mono8";
  const bool mono16 = m.encoding == "mono16";
  if (!mono8 && !mono16)
    throw Error(topic + ": image encoding '" + m.encoding + "', expected mono8 or mono16");
  if (mono16 && m.big_endian)
    throw Error(topic +
                ": big-endian mono16 images are not read (uwscan's cameras send little-endian)");
  const std::uint32_t bytes_per_pixel = mono8 ? 1 : 2;
  if (m.step != m.width * bytes_per_pixel ||
      m.data.size() != static_cast<std::size_t>(m.step) * m.height) {
    throw Error(topic + ": image of " + SizeText(m.width, m.height) + " " + m.encoding +
                " has step " + std::to_string(m.step) + " and " + std::to_string(m.data.size()) +
                " bytes (padded rows are not read)");
  }
  const auto width = static_cast<std::uint32_t>(camera_.width_px);
  const auto height = static_cast<std::uint32_t>(camera_.height_px);
  mapping::FrameRecord record;
  record.time_s = time_s;
  std::optional<acq::FrameMetadata> metadata;
  if (m.width == width && m.height == height + 1) {  // image mode
    const acq::ImageLayout l{camera_.width_px, camera_.height_px,
                             mono8 ? scanner::PixelFormat::kMono8 : scanner::PixelFormat::kMono16};
    std::optional<acq::DecodedImage> decoded = acq::DecodeImage(l, m.data);
    if (!decoded) return std::nullopt;
    metadata = decoded->metadata;
    detector_.Detect(decoded->image, &detection_);
    for (const scanner::StripePeak& p : detection_.peaks)
      record.peaks_px.emplace_back(p.u_px, p.v_px);
    if (keep_images_) {
      mapping::LogImage image{
          camera_.width_px,
          camera_.height_px,
          mono8 ? mapping::LogPixelFormat::kMono8 : mapping::LogPixelFormat::kMono16,
          {}};
      image.bytes.assign(m.data.begin(),
                         m.data.begin() + static_cast<std::ptrdiff_t>(l.row_bytes() * height));
      record.image = std::move(image);
    }
  } else if (mono16 && m.height >= 2 && m.height <= 65 &&
             (m.width == height || m.width == width)) {  // profile
    acq::ProfileLayout l;
    l.axis = m.width == height ? scanner::StripeAxis::kRows : scanner::StripeAxis::kColumns;
    l.lines = static_cast<int>(m.width);
    l.line_length_px = l.axis == scanner::StripeAxis::kRows ? camera_.width_px : camera_.height_px;
    l.peak_rows = static_cast<int>(m.height) - 1;
    std::optional<acq::DecodedProfile> decoded = acq::DecodeProfile(l, m.data);
    if (!decoded) return std::nullopt;
    metadata = decoded->metadata;
    record.peaks_px = std::move(decoded->peaks_px);
  } else {
    throw Error(topic + ": image of " + SizeText(m.width, m.height) + " " + m.encoding +
                " is neither a profile (mono16, " + std::to_string(height) + " or " +
                std::to_string(width) + " wide, 2 to 65 rows) nor an image of the " +
                SizeText(width, height) + " camera with its metadata row (" +
                SizeText(width, height + 1) + ")");
  }
  record.command = metadata->mirror_command;
  record.sweep = metadata->sweep;
  return record;
}

}  // namespace uwscan::ros
