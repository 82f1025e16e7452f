#include "apps/scanner/camera_frames.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "apps/cli/output_path.hpp"
#include "apps/cli/stop_signal.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::app {

namespace acq = scanner::acquisition;

void AddCameraOptions(CLI::App& cmd, CameraArgs& a) {
  cmd.add_option("--camera", a.camera, "camera IPv4 address (opened directly, never discovered)")
      ->required();
  cmd.add_option("--scene", a.scene,
                 "simulated camera: the scene it serves (scanner and scan pattern)")
      ->check(CLI::ExistingFile);
  cmd.add_option("--scanner", a.scanner_file, "real camera: the scanner (calibration) file")
      ->check(CLI::ExistingFile);
  cmd.add_option("--receive", a.receive, "Aravis's receive path: packet (raw packet socket) or udp")
      ->capture_default_str();
  cmd.add_option("--trigger", a.trigger, "free, software or line (Line0)")->capture_default_str();
  cmd.add_option("--pixel-format", a.pixel_format, "mono8 or mono16 (default: the camera's)");
  cmd.add_option("--packet-size", a.packet_size,
                 "GigE Vision packet size, bytes (default: the camera's)");
  cmd.add_option("--fps", a.fps, "frame rate in free run (default: the camera's)");
  cmd.add_option("--exposure-us", a.exposure_us,
                 "exposure time, microseconds (default: the camera's)");
  cmd.add_option("--gain", a.gain, "gain, camera units (default: the camera's)");
  cmd.add_option("--roi", a.roi, "region of interest x,y,width,height (pixels)")->delimiter(',');
  cmd.add_option("--buffers", a.buffers, "Aravis buffers (frames the driver holds)")
      ->capture_default_str();
  cmd.add_option("--watchdog-s", a.watchdog_s, "reopen a camera silent this long, seconds")
      ->capture_default_str();
}

acq::CameraSettings MakeCameraSettings(const CameraArgs& a) {
  if (a.scene.empty() == a.scanner_file.empty()) {
    throw Error(
        "give --scene (a simulated camera: the scene's scanner and scan pattern) or --scanner "
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
  if (a.pixel_format == "mono8")
    settings.pixel_format = scanner::PixelFormat::kMono8;
  else if (a.pixel_format == "mono16")
    settings.pixel_format = scanner::PixelFormat::kMono16;
  else if (!a.pixel_format.empty())
    throw Error("--pixel-format: unknown '" + a.pixel_format + "' (use mono8 or mono16)");
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
  if (a.scene.empty() == a.scanner_file.empty()) {
    throw Error(
        "give --scene (a simulated camera: the scene's scanner and scan pattern) or --scanner "
        "(the scanner file of a real camera)");
  }
  return mapping::MakeAcquisitionContext(a.scene, a.scanner_file, payload,
                                         "uwscan " + command + " " + UWSCAN_VERSION + " (camera " +
                                             a.camera + ", " + payload.vendor + " " +
                                             payload.model + ")");
}

void CheckNewLogPath(const std::string& path, bool force, const std::string& option) {
  CheckOutputPath(path, option);
  if (std::filesystem::exists(path)) {
    if (!force) throw Error(path + ": exists (a dive log is never overwritten; use --force)");
    if (!std::filesystem::is_regular_file(path))
      throw Error(path + ": exists and is not a file; not replaced");
  }
}

void RemoveLog(const std::string& path) {
  std::filesystem::remove(path);
  std::filesystem::remove(path + "-wal");
  std::filesystem::remove(path + "-shm");
}

ReadSummary ReadFrames(
    acq::FrameSource& source, CameraFrameDecoder& decoder, const ReadLimits& limits,
    const std::string& name,
    const std::function<void(mapping::FrameRecord&&, const acq::AcquiredFrame&)>& consume,
    const std::function<void(const ReadSummary&, double now_s)>& status) {
  mapping::ReadCallbacks callbacks;
  callbacks.consume = consume;
  if (status) {
    callbacks.status = [&status](const mapping::ReadSummary& s, double now) {
      status(ReadSummary{s, 0}, now);
    };
  }
  callbacks.gap = [&name](const acq::CameraGap& g) {
    if (g.resumed_at_s >= 0.0) {
      std::fprintf(
          stderr,
          "%s%s: camera silent after %.2f s; reopened (%d attempts), frames again at %.2f s\n",
          isatty(2) ? "\n" : "", name.c_str(), g.silent_after_s, g.reopen_attempts, g.resumed_at_s);
    } else {
      std::fprintf(stderr,
                   "%s: camera silent since %.2f s (%d reopen attempts), not back when stopped\n",
                   name.c_str(), g.silent_after_s, g.reopen_attempts);
    }
  };
  callbacks.stop_requested = [] { return StopRequested(); };
  ReadSummary summary{mapping::ReadFrames(source, decoder, limits, callbacks), 0};
  summary.stop_signal = StopSignal();
  return summary;
}

}  // namespace uwscan::app
