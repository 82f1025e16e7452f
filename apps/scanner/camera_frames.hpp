#pragma once

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mapping/inspection/live_inspection.hpp"
#include "mapping/log/dive_log.hpp"
#include "scanner/acquisition/frame_source.hpp"
#include "scanner/acquisition/mirror_driver.hpp"
#include "scanner/stripe/stripe_detector.hpp"

// What `acquire` and `inspect` share: the camera's command-line options and the settings they
// make, what a dive log's header says the frames were taken with, and a camera's frame turned
// into a dive-log frame (peaks decoded in profile mode, found by the host's detector in image
// mode).
namespace uwscan::app {

struct CameraArgs {
  std::string camera;        // IPv4 address
  std::string scene;         // a simulated camera: the scene it serves
  std::string scanner_file;  // a real camera: the scanner (calibration) file
  std::string receive = "packet";
  std::string trigger = "free";
  std::string pixel_format;
  int packet_size = 0;
  double fps = 0.0;
  double exposure_us = 0.0;
  double gain = -1.0;
  std::vector<int> roi;
  int buffers = 256;
  double watchdog_s = 2.0;
};

// --camera (required), --scene, --scanner, --receive, --trigger, --pixel-format, --packet-size,
// --fps, --exposure-us, --gain, --roi, --buffers, --watchdog-s.
void AddCameraOptions(CLI::App& command, CameraArgs& args);

// Throws uwscan::Error naming the option when a value is unknown or out of range, or when
// neither or both of --scene and --scanner are given.
scanner::acquisition::CameraSettings MakeCameraSettings(const CameraArgs& args);

struct AcquisitionContext {
  mapping::DiveLogHeader header;  // scanner, scan pattern (and scene text when simulated)
  scanner::StripeDetectorOptions detector;  // how image-mode frames are searched
  // The camera on the vehicle: the scene's mount when simulated, identity for a real camera.
  Eigen::Isometry3d T_V_C = Eigen::Isometry3d::Identity();
};

// `command`: "acquire", "inspect" (the log's producer names it). Throws uwscan::Error when the
// scene or the scanner file cannot be read.
AcquisitionContext MakeContext(const CameraArgs& args, const scanner::acquisition::PayloadDescription& payload,
                               const std::string& command);

// Turns a camera's frames into dive-log frames: profile payloads decoded, image payloads
// searched by the host's StripeDetector. Time, mirror command and sweep come from the frame's
// metadata row; a camera without one gets the camera's clock and the scan pattern's command
// for its frame number. Not thread-safe.
class CameraFrameDecoder {
 public:
  // keep_images: image mode, each image goes into its record as well. Throws uwscan::Error
  // when the camera sends profiles without a metadata row (the peaks' mirror command would be
  // unknown), or profiles while images are to be kept.
  CameraFrameDecoder(const scanner::acquisition::PayloadDescription& payload, const AcquisitionContext& context,
                     bool keep_images);

  // std::nullopt when the payload does not decode (packets lost: its checksum fails).
  std::optional<mapping::FrameRecord> Decode(const scanner::acquisition::AcquiredFrame& frame);

 private:
  scanner::acquisition::PayloadDescription payload_;
  scanner::StripeDetector detector_;
  scanner::acquisition::SimulatedMirrorDriver pattern_driver_;
  scanner::StripeDetection detection_;
  bool keep_images_;
};

// A decoded frame with its times for live inspection: received at the host's timestamp;
// captured at the camera's, when the camera's clock is the host's (within a second of it: a
// PTP-synchronised camera, or the fake camera), else unknown (a camera counting from power-up).
mapping::InspectionFrame ToInspectionFrame(mapping::FrameRecord&& record,
                                           const scanner::acquisition::AcquiredFrame& frame);

// A new dive log's path, checked before the camera is opened: its folder exists; an existing
// file is replaced only with `force` (RemoveLog, once the camera answered). Throws
// uwscan::Error naming `option` otherwise.
void CheckNewLogPath(const std::string& path, bool force, const std::string& option);
void RemoveLog(const std::string& path);  // the file and SQLite's -wal and -shm beside it

struct ReadLimits {
  std::int64_t frames = 0;  // stop after this many decoded frames (0: no limit)
  double seconds = 0.0;     // stop after this long (0: no limit)
};

struct ReadSummary {
  std::int64_t frames = 0;  // decoded and handed on
  std::int64_t peaks = 0;
  std::int64_t undecodable = 0;
  double seconds = 0.0;  // since the camera started
  scanner::acquisition::FrameSourceStatistics source;
  int stop_signal = 0;  // SIGINT or SIGTERM when one stopped it
};

// Starts the camera and hands every decoded frame to `consume` (with the camera's frame, for
// its timestamps) until the limits are reached or a stop is requested (stop_signal.hpp); calls
// `status` about once a second; reports camera gaps (watchdog reopens) on stderr, prefixed by
// `name`. Software trigger mode: triggers one frame at a time. Stops the camera before it
// returns.
ReadSummary ReadFrames(scanner::acquisition::FrameSource& source, CameraFrameDecoder& decoder,
                       const ReadLimits& limits, const std::string& name,
                       const std::function<void(mapping::FrameRecord&&, const scanner::acquisition::AcquiredFrame&)>& consume,
                       const std::function<void(const ReadSummary&, double now_s)>& status);

}  // namespace uwscan::app
