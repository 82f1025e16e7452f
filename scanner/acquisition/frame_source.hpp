#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "scanner/acquisition/frame_encoding.hpp"
#include "scanner/stripe/stripe_image.hpp"

// Frames from a GenICam GigE Vision camera through Aravis 0.8. Aravis stays inside the .cpp.
namespace uwscan::scanner::acquisition {

enum class TriggerMode : std::uint8_t {
  kFreeRun = 0,  // the camera runs at its frame rate
  kSoftware,     // a frame per FrameSource::SoftwareTrigger()
  kLine,         // a frame per pulse on trigger_line (the mirror driver's trigger)
};
const char* ToString(TriggerMode mode);  // "free", "software", "line"
std::optional<TriggerMode> TriggerModeFromString(const std::string& name);

// Aravis receives GigE Vision stream packets either through a raw packet socket (its default,
// the faster; inside a private network namespace it works and Aravis does not fall back when it
// fails) or through an ordinary UDP socket.
enum class ReceivePath : std::uint8_t { kPacketSocket = 0, kUdpSocket };
const char* ToString(ReceivePath path);  // "packet", "udp"
std::optional<ReceivePath> ReceivePathFromString(const std::string& name);

struct CameraSettings {
  // IPv4 address of the camera. The camera is opened there directly; uwscan never runs
  // Aravis's device discovery, which broadcasts on every interface.
  std::string address = "127.0.0.1";
  // Region of interest, pixels of the payload; width_px = 0 keeps the camera's region.
  int roi_x_px = 0;
  int roi_y_px = 0;
  int roi_width_px = 0;
  int roi_height_px = 0;
  double exposure_us = 0.0;  // microseconds; 0 keeps the camera's
  double gain = -1.0;        // camera units (GainRaw or Gain); < 0 keeps the camera's
  std::optional<PixelFormat> pixel_format;  // Mono8 or Mono16; nullopt keeps the camera's
  TriggerMode trigger = TriggerMode::kFreeRun;
  std::string trigger_line = "Line0";
  double frame_rate_hz = 0.0;  // free run only; 0 keeps the camera's
  int packet_size_bytes = 0;   // GigE Vision stream packet size, bytes; 0 keeps the camera's
  ReceivePath receive_path = ReceivePath::kPacketSocket;
  // Aravis buffers the camera's frames land in. When every buffer waits to be read (the reader
  // is behind), Aravis drops the next frames; they are counted as lost.
  int buffers = 64;
  // A camera that sends nothing for this long while acquiring (it went silent, was unplugged or
  // restarted) is closed and reopened with the same settings; the gap is recorded.
  double watchdog_s = 2.0;
  // Frames still incomplete after this long are handed over incomplete (Aravis's frame
  // retention), seconds.
  double frame_retention_s = 0.2;
  // When opening, how long to wait for another controller to let go of the camera, seconds. A
  // program that died holding it (a killed acquire) keeps it until the camera's heartbeat
  // timeout (GigE Vision's default: 3 s) runs out; a live one keeps it.
  double control_wait_s = 5.0;

  // Throws uwscan::Error naming the field when a value is out of range.
  void Check() const;
};

// What the camera's GenICam features say its payload carries.
struct PayloadDescription {
  bool uwscan_layout = false;    // the camera describes its payload with the Uwscan* features
  bool profile = false;          // profile mode (peaks); else image mode
  ProfileLayout profile_layout;  // valid when profile
  ImageLayout image_layout;      // valid when !profile: the image rows (without metadata row)
  bool metadata_row = false;     // the payload's last row is a metadata row
  int payload_width_px = 0;
  int payload_height_px = 0;
  PixelFormat format = PixelFormat::kMono8;
  std::string vendor;
  std::string model;
};

struct AcquiredFrame {
  std::int64_t sequence = 0;      // frames handed out by this source, 0 first
  std::uint16_t frame_id = 0;     // the camera's 16-bit GigE Vision block id
  std::int64_t frame_number = 0;  // unwrapped frame id within the session, 0 first
  std::int64_t lost_before = 0;   // frames the camera sent that never came, just before this
  int session = 0;                // how many times the camera was reopened before this frame
  std::uint64_t camera_timestamp_ns = 0;  // the camera's clock
  std::uint64_t host_timestamp_ns = 0;    // the host's clock (real time) when Aravis got it
  std::vector<std::uint8_t> payload;      // a copy of the camera's bytes
};

// One time the camera went silent and was reopened.
struct CameraGap {
  double silent_after_s = 0.0;  // seconds since Start() of the last frame before the gap
  double resumed_at_s = -1.0;   // seconds since Start() of the first frame after it (-1: not yet)
  int reopen_attempts = 0;
};

struct FrameSourceStatistics {
  std::int64_t frames = 0;             // complete frames handed out
  std::int64_t lost_frames = 0;        // ids never received + frames received incomplete
  std::int64_t incomplete_frames = 0;  // part of lost_frames: packets missing at the deadline
  std::int64_t stale_frames = 0;       // late or repeated ids, dropped
  std::int64_t bytes = 0;              // payload bytes handed out
  std::vector<CameraGap> gaps;
  // Aravis's own counters over the current session, for comparison (they count gaps and
  // packets, not frames).
  std::uint64_t aravis_missing_frames = 0;
  std::uint64_t aravis_underruns = 0;
};

// Opens a camera, applies the settings and streams. The Aravis stream thread's callback only
// moves each finished buffer to a bounded queue (at most `buffers` entries, so it never
// blocks); Next() copies the oldest buffer's bytes out and gives the buffer back to Aravis.
// Lost frames are counted from the unwrapped 16-bit frame ids, per session. Not thread-safe:
// one thread calls everything (Next() also runs the watchdog and reopens the camera).
class FrameSource {
 public:
  // Opens the camera at settings.address and applies every setting. Throws uwscan::Error
  // naming the address when no GigE Vision camera answers there, or naming the setting the
  // camera refused.
  explicit FrameSource(const CameraSettings& settings);
  ~FrameSource();  // stops the acquisition and closes the camera
  FrameSource(const FrameSource&) = delete;
  FrameSource& operator=(const FrameSource&) = delete;

  const PayloadDescription& payload() const;
  const CameraSettings& settings() const;

  // Starts streaming. Throws uwscan::Error when the camera refuses.
  void Start();
  // The next complete frame, or nullopt when none came within `timeout`. Runs the watchdog.
  std::optional<AcquiredFrame> Next(std::chrono::milliseconds timeout);
  // Software trigger mode: asks the camera for one frame.
  void SoftwareTrigger();
  // Stops streaming (idempotent).
  void Stop();

  FrameSourceStatistics statistics() const;
  // Seconds since Start() on the host's steady clock.
  double ElapsedSeconds() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace uwscan::scanner::acquisition
