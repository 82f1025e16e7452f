#include "mapping/inspection/camera_frames.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"

namespace uwscan::mapping {

namespace acq = scanner::acquisition;

namespace {

std::string FileText(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

AcquisitionContext MakeAcquisitionContext(const std::string& scene_path,
                                          const std::string& scanner_file,
                                          const acq::PayloadDescription& payload,
                                          const std::string& producer) {
  if (scene_path.empty() == scanner_file.empty()) {
    throw Error(
        "give the scene a simulated camera serves or the scanner file of a real camera (one of "
        "them)");
  }
  AcquisitionContext c;
  c.header.producer = producer;
  if (!scene_path.empty()) {
    const scanner::sim::Scene scene = scanner::sim::LoadScene(scene_path);
    const scanner::sim::Simulator simulator(scene);
    c.header.scanner = simulator.scanner();
    c.header.scan_pattern = simulator.scan_pattern();
    c.header.scene_yaml = FileText(scene_path);
    c.detector = scene.detector;
    c.T_V_C = scene.trajectory.T_V_C;
  } else {
    c.header.scanner = scanner::LoadScanner(scanner_file);
    c.header.scan_pattern.kind = c.header.scanner.kind();
    c.detector.axis = payload.profile_layout.axis;
  }
  return c;
}

CameraFrameDecoder::CameraFrameDecoder(const acq::PayloadDescription& payload,
                                       const AcquisitionContext& context, bool keep_images)
    : payload_(payload),
      detector_(context.detector),
      pattern_driver_(context.header.scan_pattern),
      keep_images_(keep_images) {
  if (!payload.metadata_row && payload.profile)
    throw Error("the camera sends profiles without a metadata row");
  if (keep_images && payload.profile) {
    throw Error("--images: the camera sends profiles (peaks found on the camera), not images");
  }
}

std::optional<FrameRecord> CameraFrameDecoder::Decode(const acq::AcquiredFrame& frame) {
  FrameRecord record;
  std::optional<acq::FrameMetadata> metadata;
  if (payload_.profile) {
    std::optional<acq::DecodedProfile> decoded =
        acq::DecodeProfile(payload_.profile_layout, frame.payload);
    if (!decoded) return std::nullopt;
    metadata = decoded->metadata;
    record.peaks_px = std::move(decoded->peaks_px);
  } else {
    const acq::ImageLayout& l = payload_.image_layout;
    scanner::StripeImage image;
    if (payload_.metadata_row) {
      std::optional<acq::DecodedImage> decoded = acq::DecodeImage(l, frame.payload);
      if (!decoded) return std::nullopt;
      metadata = decoded->metadata;
      image = decoded->image;
    } else {
      image = {frame.payload.data(), l.width_px, l.height_px,
               static_cast<std::ptrdiff_t>(l.row_bytes()), l.format};
    }
    detector_.Detect(image, &detection_);
    record.peaks_px.reserve(detection_.peaks.size());
    for (const scanner::StripePeak& p : detection_.peaks)
      record.peaks_px.emplace_back(p.u_px, p.v_px);
    if (keep_images_) {
      LogImage log_image;
      log_image.width_px = image.width_px;
      log_image.height_px = image.height_px;
      log_image.format = image.format == scanner::PixelFormat::kMono8 ? LogPixelFormat::kMono8
                                                                      : LogPixelFormat::kMono16;
      const auto* bytes = static_cast<const std::uint8_t*>(image.data);
      log_image.bytes.assign(bytes,
                             bytes + l.row_bytes() * static_cast<std::size_t>(image.height_px));
      record.image = std::move(log_image);
    }
  }
  if (metadata) {
    record.time_s = static_cast<double>(metadata->timestamp_ns) * 1e-9;
    record.command = metadata->mirror_command;
    record.sweep = metadata->sweep;
  } else {
    // A camera without uwscan's metadata row: the camera's clock, and the mirror driver's
    // command for this trigger (frame numbers count from the first frame of the session).
    const acq::MirrorCommand c =
        pattern_driver_.CommandOf(static_cast<std::uint64_t>(frame.frame_number));
    record.time_s = static_cast<double>(frame.camera_timestamp_ns) * 1e-9;
    record.command = c.command;
    record.sweep = c.sweep;
  }
  return record;
}

InspectionFrame ToInspectionFrame(FrameRecord&& record, const acq::AcquiredFrame& frame) {
  // A camera clock further than this from the host's is another clock.
  constexpr double kSameClock_s = 1.0;
  InspectionFrame f;
  f.record = std::move(record);
  f.receive_time_s = static_cast<double>(frame.host_timestamp_ns) * 1e-9;
  const double camera_s = static_cast<double>(frame.camera_timestamp_ns) * 1e-9;
  if (std::abs(camera_s - f.receive_time_s) < kSameClock_s) f.capture_time_s = camera_s;
  return f;
}

}  // namespace uwscan::mapping
