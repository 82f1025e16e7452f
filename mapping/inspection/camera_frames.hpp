#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>

#include "mapping/inspection/live_inspection.hpp"
#include "mapping/log/dive_log.hpp"
#include "scanner/acquisition/frame_source.hpp"
#include "scanner/acquisition/mirror_driver.hpp"
#include "scanner/stripe/stripe_detector.hpp"

// A camera's frames as dive-log frames, for every front door that reads a camera (`acquire`,
// `inspect`, `uwscan ros inspect`): what the log's header says they were taken with, and each
// frame decoded (profile mode) or searched by the host's detector (image mode).
namespace uwscan::mapping {

struct AcquisitionContext {
  DiveLogHeader header;                     // scanner, scan pattern (and scene text when simulated)
  scanner::StripeDetectorOptions detector;  // how image-mode frames are searched
  // The camera on the vehicle: the scene's mount when simulated, identity for a real camera.
  Eigen::Isometry3d T_V_C = Eigen::Isometry3d::Identity();
};

// A simulated camera's context from the scene it serves (`scene_path`), or a real camera's from
// its scanner file (`scanner_file`): give exactly one. `producer` goes into the log's header.
// Throws uwscan::Error when neither or both are given, or a file cannot be read.
AcquisitionContext MakeAcquisitionContext(const std::string& scene_path,
                                          const std::string& scanner_file,
                                          const scanner::acquisition::PayloadDescription& payload,
                                          const std::string& producer);

// Turns a camera's frames into dive-log frames: profile payloads decoded, image payloads
// searched by the host's StripeDetector. Time, mirror command and sweep come from the frame's
// metadata row; a camera without one gets the camera's clock and the scan pattern's command
// for its frame number. Not thread-safe.
class CameraFrameDecoder {
 public:
  // keep_images: image mode, each image goes into its record as well. Throws uwscan::Error
  // when the camera sends profiles without a metadata row (the peaks' mirror command would be
  // unknown), or profiles while images are to be kept.
  CameraFrameDecoder(const scanner::acquisition::PayloadDescription& payload,
                     const AcquisitionContext& context, bool keep_images);

  // std::nullopt when the payload does not decode (packets lost: its checksum fails).
  std::optional<FrameRecord> Decode(const scanner::acquisition::AcquiredFrame& frame);

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
InspectionFrame ToInspectionFrame(FrameRecord&& record,
                                  const scanner::acquisition::AcquiredFrame& frame);

}  // namespace uwscan::mapping
