#include "apps/scanner/camera_frames.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "apps/cli/output_path.hpp"
#include "apps/cli/stop_signal.hpp"
#include "apps/cli/text_file.hpp"
#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"

namespace uwscan::app {

namespace acq = scanner::acquisition;

void AddCameraOptions(CLI::App& cmd, CameraArgs& a) {
  cmd.add_option("--camera", a.camera, "camera IPv4 address (opened directly, never discovered)")->required();
  cmd.add_option("--scene", a.scene, "simulated camera: the scene it serves (scanner and scan pattern)")
      ->check(CLI::ExistingFile);
  cmd.add_option("--scanner", a.scanner_file, "real camera: the scanner (calibration) file")
      ->check(CLI::ExistingFile);
  cmd.add_option("--receive", a.receive, "Aravis's receive path: packet (raw packet socket) or udp")
      ->capture_default_str();
  cmd.add_option("--trigger", a.trigger, "free, software or line (Line0)")->capture_default_str();
  cmd.add_option("--pixel-format", a.pixel_format, "mono8 or mono16 (default: the camera's)");
  cmd.add_option("--packet-size", a.packet_size, "GigE Vision packet size, bytes (default: the camera's)");
  cmd.add_option("--fps", a.fps, "frame rate in free run (default: the camera's)");
  cmd.add_option("--exposure-us", a.exposure_us, "exposure time, microseconds (default: the camera's)");
  cmd.add_option("--gain", a.gain, "gain, camera units (default: the camera's)");
  cmd.add_option("--roi", a.roi, "region of interest x,y,width,height (pixels)")->delimiter(',');
  cmd.add_option("--buffers", a.buffers, "Aravis buffers (frames the driver holds)")->capture_default_str();
  cmd.add_option("--watchdog-s", a.watchdog_s, "reopen a camera silent this long, seconds")->capture_default_str();
}

acq::CameraSettings MakeCameraSettings(const CameraArgs& a) {
  if (a.scene.empty() == a.scanner_file.empty()) {
    throw Error("give --scene (a simulated camera: the scene's scanner and scan pattern) or --scanner "
                "(the scanner file of a real camera)");
  }
  acq::CameraSettings settings;
  settings.address = a.camera;
  const std::optional<acq::ReceivePath> path = acq::ReceivePathFromString(a.receive);
  if (!path) throw Error("--receive: unknown '" + a.receive + "' (use packet or udp)");
  settings.receive_path = *path;
  const std::optional<acq::TriggerMode> trigger = acq::TriggerModeFromString(a.trigger);
  if (!trigger) throw Error("--trigger: unknown '" + a.trigger + "' (use free, software or line)");
  settings.trigger = *trigger;
  if (a.pixel_format == "mono8") settings.pixel_format = scanner::PixelFormat::kMono8;
  else if (a.pixel_format == "mono16") settings.pixel_format = scanner::PixelFormat::kMono16;
  else if (!a.pixel_format.empty()) throw Error("--pixel-format: unknown '" + a.pixel_format + "' (use mono8 or mono16)");
  if (!a.roi.empty()) {
    if (a.roi.size() != 4) throw Error("--roi: expected x,y,width,height");
    settings.roi_x_px = a.roi[0];
    settings.roi_y_px = a.roi[1];
    settings.roi_width_px = a.roi[2];
    settings.roi_height_px = a.roi[3];
  }
  settings.packet_size_bytes = a.packet_size;
  settings.frame_rate_hz = a.fps;
  settings.exposure_us = a.exposure_us;
  settings.gain = a.gain;
  settings.buffers = a.buffers;
  settings.watchdog_s = a.watchdog_s;
  settings.Check();
  return settings;
}

AcquisitionContext MakeContext(const CameraArgs& a, const acq::PayloadDescription& payload,
                               const std::string& command) {
  AcquisitionContext c;
  c.header.producer = "uwscan " + command + " " + UWSCAN_VERSION + " (camera " + a.camera + ", " + payload.vendor +
                      " " + payload.model + ")";
  if (!a.scene.empty()) {
    const scanner::sim::Scene scene = scanner::sim::LoadScene(a.scene);
    const scanner::sim::Simulator simulator(scene);
    c.header.scanner = simulator.scanner();
    c.header.scan_pattern = simulator.scan_pattern();
    c.header.scene_yaml = ReadText(a.scene);
    c.detector = scene.detector;
    c.T_V_C = scene.trajectory.T_V_C;
  } else {
    c.header.scanner = scanner::LoadScanner(a.scanner_file);
    c.header.scan_pattern.kind = c.header.scanner.kind();
    c.detector.axis = payload.profile_layout.axis;
  }
  return c;
}

CameraFrameDecoder::CameraFrameDecoder(const acq::PayloadDescription& payload, const AcquisitionContext& context,
                                       bool keep_images)
    : payload_(payload),
      detector_(context.detector),
      pattern_driver_(context.header.scan_pattern),
      keep_images_(keep_images) {
  if (!payload.metadata_row && payload.profile) throw Error("the camera sends profiles without a metadata row");
  if (keep_images && payload.profile) {
    throw Error("--images: the camera sends profiles (peaks found on the camera), not images");
  }
}

std::optional<mapping::FrameRecord> CameraFrameDecoder::Decode(const acq::AcquiredFrame& frame) {
  mapping::FrameRecord record;
  std::optional<acq::FrameMetadata> metadata;
  if (payload_.profile) {
    std::optional<acq::DecodedProfile> decoded = acq::DecodeProfile(payload_.profile_layout, frame.payload);
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
      image = {frame.payload.data(), l.width_px, l.height_px, static_cast<std::ptrdiff_t>(l.row_bytes()), l.format};
    }
    detector_.Detect(image, &detection_);
    record.peaks_px.reserve(detection_.peaks.size());
    for (const scanner::StripePeak& p : detection_.peaks) record.peaks_px.emplace_back(p.u_px, p.v_px);
    if (keep_images_) {
      mapping::LogImage log_image;
      log_image.width_px = image.width_px;
      log_image.height_px = image.height_px;
      log_image.format = image.format == scanner::PixelFormat::kMono8 ? mapping::LogPixelFormat::kMono8
                                                                       : mapping::LogPixelFormat::kMono16;
      const auto* bytes = static_cast<const std::uint8_t*>(image.data);
      log_image.bytes.assign(bytes, bytes + l.row_bytes() * static_cast<std::size_t>(image.height_px));
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
    const acq::MirrorCommand c = pattern_driver_.CommandOf(static_cast<std::uint64_t>(frame.frame_number));
    record.time_s = static_cast<double>(frame.camera_timestamp_ns) * 1e-9;
    record.command = c.command;
    record.sweep = c.sweep;
  }
  return record;
}

mapping::InspectionFrame ToInspectionFrame(mapping::FrameRecord&& record, const acq::AcquiredFrame& frame) {
  // A camera clock further than this from the host's is another clock.
  constexpr double kSameClock_s = 1.0;
  mapping::InspectionFrame f;
  f.record = std::move(record);
  f.receive_time_s = static_cast<double>(frame.host_timestamp_ns) * 1e-9;
  const double camera_s = static_cast<double>(frame.camera_timestamp_ns) * 1e-9;
  if (std::abs(camera_s - f.receive_time_s) < kSameClock_s) f.capture_time_s = camera_s;
  return f;
}

void CheckNewLogPath(const std::string& path, bool force, const std::string& option) {
  CheckOutputPath(path, option);
  if (std::filesystem::exists(path)) {
    if (!force) throw Error(path + ": exists (a dive log is never overwritten; use --force)");
    if (!std::filesystem::is_regular_file(path)) throw Error(path + ": exists and is not a file; not replaced");
  }
}

void RemoveLog(const std::string& path) {
  std::filesystem::remove(path);
  std::filesystem::remove(path + "-wal");
  std::filesystem::remove(path + "-shm");
}

ReadSummary ReadFrames(acq::FrameSource& source, CameraFrameDecoder& decoder,
                       const ReadLimits& limits, const std::string& name,
                       const std::function<void(mapping::FrameRecord&&, const acq::AcquiredFrame&)>& consume,
                       const std::function<void(const ReadSummary&, double now_s)>& status) {
  const bool software_trigger = source.settings().trigger == acq::TriggerMode::kSoftware;
  ReadSummary summary;
  source.Start();
  if (software_trigger) source.SoftwareTrigger();
  double last_status = 0.0;
  std::size_t gaps_reported = 0;
  while (!StopRequested()) {
    if (limits.frames > 0 && summary.frames >= limits.frames) break;
    if (limits.seconds > 0.0 && source.ElapsedSeconds() >= limits.seconds) break;
    std::optional<acq::AcquiredFrame> frame = source.Next(std::chrono::milliseconds(100));
    const double now = source.ElapsedSeconds();
    summary.source = source.statistics();
    while (gaps_reported < summary.source.gaps.size() && summary.source.gaps[gaps_reported].resumed_at_s >= 0.0) {
      const acq::CameraGap& g = summary.source.gaps[gaps_reported++];
      std::fprintf(stderr, "%s%s: camera silent after %.2f s; reopened (%d attempts), frames again at %.2f s\n",
                   isatty(2) ? "\n" : "", name.c_str(), g.silent_after_s, g.reopen_attempts, g.resumed_at_s);
    }
    if (status && now - last_status >= 1.0) {
      status(summary, now);
      last_status = now;
    }
    if (!frame) continue;
    if (software_trigger) source.SoftwareTrigger();
    std::optional<mapping::FrameRecord> record = decoder.Decode(*frame);
    if (!record) {
      ++summary.undecodable;
      continue;
    }
    summary.peaks += static_cast<std::int64_t>(record->peaks_px.size());
    consume(std::move(*record), *frame);
    ++summary.frames;
  }
  summary.stop_signal = StopSignal();
  summary.seconds = source.ElapsedSeconds();
  source.Stop();
  summary.source = source.statistics();
  for (const acq::CameraGap& g : summary.source.gaps) {
    if (g.resumed_at_s < 0.0) {
      std::fprintf(stderr, "%s: camera silent since %.2f s (%d reopen attempts), not back when stopped\n",
                   name.c_str(), g.silent_after_s, g.reopen_attempts);
    }
  }
  return summary;
}

}  // namespace uwscan::app
