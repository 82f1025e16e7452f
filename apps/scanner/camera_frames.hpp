#pragma once

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mapping/inspection/camera_frames.hpp"
#include "mapping/inspection/camera_reader.hpp"
#include "mapping/inspection/live_inspection.hpp"
#include "mapping/log/dive_log.hpp"
#include "scanner/acquisition/frame_source.hpp"
#include "scanner/acquisition/mirror_driver.hpp"
#include "scanner/stripe/stripe_detector.hpp"

// What the camera commands (`acquire`, `inspect`, `ros inspect`) share on the command line: the
// camera's options and the settings they make, the log's path, and the camera loop with the
// stop signal and messages on stderr (the loop and the decoder themselves are in
// mapping/inspection/camera_reader.hpp and camera_frames.hpp).
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

using AcquisitionContext = mapping::AcquisitionContext;
using CameraFrameDecoder = mapping::CameraFrameDecoder;
using mapping::ToInspectionFrame;

// `command`: "acquire", "inspect" (the log's producer names it). Throws uwscan::Error when the
// scene or the scanner file cannot be read.
AcquisitionContext MakeContext(const CameraArgs& args,
                               const scanner::acquisition::PayloadDescription& payload,
                               const std::string& command);

// A new dive log's path, checked before the camera is opened: its folder exists; an existing
// file is replaced only with `force` (RemoveLog, once the camera answered). Throws
// uwscan::Error naming `option` otherwise.
void CheckNewLogPath(const std::string& path, bool force, const std::string& option);
void RemoveLog(const std::string& path);  // the file and SQLite's -wal and -shm beside it

using ReadLimits = mapping::ReadLimits;

struct ReadSummary : mapping::ReadSummary {
  int stop_signal = 0;  // SIGINT or SIGTERM when one stopped it
};

// mapping::ReadFrames until the limits or a stop signal (stop_signal.hpp); camera gaps (watchdog
// reopens) reported on stderr, prefixed by `name`.
ReadSummary ReadFrames(
    scanner::acquisition::FrameSource& source, CameraFrameDecoder& decoder,
    const ReadLimits& limits, const std::string& name,
    const std::function<void(mapping::FrameRecord&&, const scanner::acquisition::AcquiredFrame&)>&
        consume,
    const std::function<void(const ReadSummary&, double now_s)>& status);

}  // namespace uwscan::app
