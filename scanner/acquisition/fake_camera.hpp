#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "scanner/acquisition/frame_encoding.hpp"
#include "scanner/acquisition/mirror_driver.hpp"
#include "scanner/sim/simulator.hpp"

// A GigE Vision camera without hardware: Aravis's ArvGvFakeCamera, described by uwscan's own
// GenICam XML (data/genicam/uwscan_fake_camera.xml), serving the simulator's frames of a scene.
// Aravis stays inside the .cpp.
namespace uwscan::scanner::acquisition {

enum class FakeCameraMode : std::uint8_t { kImage = 0, kProfile };
const char* ToString(FakeCameraMode mode);  // "image", "profile"

struct FakeCameraOptions {
  std::string address = "127.0.0.1";  // the interface address (or name) it answers on
  std::string serial = "UWSCAN-SIM";
  FakeCameraMode mode = FakeCameraMode::kProfile;
  // Frames per second; 0 = the scan pattern's rate (the mirror driver's trigger rate). Aravis's
  // fake camera counts frame periods in whole microseconds and runs at 1000 frames/s at most.
  double frame_rate_hz = 0.0;
  // Fraction of frames dropped whole (every packet of the frame is withheld), drawn per frame
  // from `seed`. In [0, 1).
  double loss_ratio = 0.0;
  std::uint64_t seed = 1;
  int peak_rows = 4;  // profile mode: peaks carried per image line, [1, 64]
  int threads = 0;    // frames prepared in parallel at start; 0 = OpenMP's default
  void Check() const;
};

struct FakeCameraStatistics {
  std::uint64_t frames_sent = 0;     // frames the camera filled and sent (dropped ones included)
  std::uint64_t frames_dropped = 0;  // of those, withheld whole by loss_ratio
  std::uint64_t peaks_dropped = 0;   // profile mode: peaks beyond peak_rows on their line
};

// Serves the simulator's frames, frame counter n showing simulated frame n mod frame_count
// (the dive again and again, sweeps numbered on) with the mirror command the simulated mirror
// driver gives trigger n; every frame of the scene is prepared (simulated, rendered, encoded)
// at construction. Image mode needs a scene with an image stage on; it serves the rendered
// frame (Mono8 or Mono16 as the camera's PixelFormat says, converted when it differs from the
// scene's) and honours the region of interest. Profile mode serves the exact (or simulated)
// peaks. Exposure and gain are recorded (exposure in each frame's metadata row) but do not
// change the simulated pixels; line triggers are not implemented by Aravis's fake camera (it
// free-runs, or answers software triggers).
class FakeCamera {
 public:
  // Prepares the frames and starts answering on options.address. Throws uwscan::Error when the
  // options are bad, image mode is asked of a scene that renders no frames, the simulated
  // mirror driver disagrees with the simulator about a frame's command, or the camera cannot
  // start (address not found, GigE Vision port 3956 taken).
  FakeCamera(const sim::Simulator& simulator, const FakeCameraOptions& options,
             const std::function<void(double)>& progress = {});
  ~FakeCamera();
  FakeCamera(const FakeCamera&) = delete;
  FakeCamera& operator=(const FakeCamera&) = delete;

  FakeCameraStatistics statistics() const;
  // The payload's shape: image rows and metadata row, or the profile.
  std::size_t payload_bytes() const;
  double frame_rate_hz() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace uwscan::scanner::acquisition
