#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>

#include "mapping/log/dive_log.hpp"
#include "ros/bridge/messages.hpp"
#include "scanner/acquisition/frame_encoding.hpp"
#include "scanner/optics/pinhole_camera.hpp"
#include "scanner/stripe/stripe_detector.hpp"

// A camera frame as a sensor_msgs/Image: the payload uwscan's cameras send
// (scanner/acquisition/frame_encoding.hpp), so that a bag or an image topic carries what the
// camera sent. Profile mode: mono16, width = image lines, height = peak rows + 1; image mode:
// mono8 or mono16, the sensor's rows and one metadata row below them. Either way the mirror
// command and the sweep ride in the metadata row; the frame's time is the message's stamp.
namespace uwscan::ros {

// Finds, frame by frame, the profile layout that carries every peak of a dive whole: peaks on
// line centres (integral v: axis kRows; integral u: kColumns), as many peak rows as the busiest
// line needs.
class ProfileLayoutFinder {
 public:
  void Add(const mapping::FrameRecord& frame);
  // Throws uwscan::Error when the peaks lie on no common line grid or a line needs more than 64.
  scanner::acquisition::ProfileLayout Layout(const scanner::PinholeCamera& camera) const;

 private:
  bool rows_ = true;
  bool columns_ = true;
  int busiest_row_ = 1;
  int busiest_column_ = 1;
};

// The frame as the camera would send it: its image (image mode) when it has one, else its
// peaks (profile mode, `layout`). `counter`: the camera's frame counter. Throws uwscan::Error
// when a peak does not fit the layout.
ImageMessage FrameToImage(const mapping::FrameRecord& frame,
                          const scanner::acquisition::ProfileLayout& layout, std::uint64_t counter,
                          const Header& header);

// Turns images of a topic back into frames. Not thread-safe.
class FrameImageDecoder {
 public:
  // camera: the scanner's (its size tells a profile from an image); detector: how image-mode
  // frames are searched; keep_images: image mode, the image goes into the frame as well.
  FrameImageDecoder(const scanner::PinholeCamera& camera,
                    const scanner::StripeDetectorOptions& detector, bool keep_images);

  // The frame at dive-log time `time_s`. Throws uwscan::Error naming `topic` when the encoding
  // or the size is not one of a payload above; std::nullopt when the metadata row does not
  // decode (packets lost on the camera's link: its checksum fails).
  std::optional<mapping::FrameRecord> Decode(const ImageMessage& image, double time_s,
                                             const std::string& topic);

 private:
  scanner::PinholeCamera camera_;
  scanner::StripeDetector detector_;
  scanner::StripeDetection detection_;
  bool keep_images_;
};

}  // namespace uwscan::ros
