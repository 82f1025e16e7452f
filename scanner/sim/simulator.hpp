#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "scanner/lasers/scan_pattern.hpp"
#include "scanner/lasers/scanner.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/stripe/stripe_render.hpp"

namespace uwscan::scanner::sim {

// One simulated camera frame: what the scanner records, and the truth behind it.
struct SimulatedFrame {
  std::int64_t index = 0;
  double time_s = 0.0;
  int command = 0;  // galvo: mirror step; MEMS: line index
  int sweep = 0;
  std::vector<Eigen::Vector2d> peaks_px;
  // Truth per peak: the lit surface point (NaN for a detected peak that matches no lit point,
  // e.g. noise) and the scene object it lies on (-1 for none).
  std::vector<Eigen::Vector3d> truth_W;
  std::vector<std::int32_t> object_ids;
  // The exact crossing of the stripe with the peak's image line (NaN for no match): what the
  // peak would be without noise, to measure a detector's error against.
  std::vector<Eigen::Vector2d> crossing_px;
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();  // true camera pose used
  std::optional<StripeFrame> image;                         // when an image stage is on
};

// Each peak's error along the detection axis (x for kRows), px: detected minus crossing_px, for
// the peaks that match a crossing.
std::vector<double> PeakErrorsPx(const SimulatedFrame& frame, StripeAxis axis);

// What the vehicle's navigation reports (the truth, plus drift when that effect is on).
struct NavigationSample {
  double time_s = 0.0;
  Eigen::Isometry3d T_W_V = Eigen::Isometry3d::Identity();
};

// Simulates a scene frame by frame: the scanner's light for each frame (galvanometer step or
// MEMS line, with mirror dynamics when on) is ray cast into the scene with Embree, the stripe's
// exact crossings with the image lines are solved for through the camera viewport, and, when an
// image stage is on, a frame is rendered and its stripe detected. Frame(i) is deterministic
// (seeded by the scene seed and i) and safe to call from several threads.
class Simulator {
 public:
  explicit Simulator(const Scene& scene);
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  std::int64_t frame_count() const;
  SimulatedFrame Frame(std::int64_t index) const;

  // Navigation over the dive at `rate_hz` (the true path, or with drift when that effect is on).
  std::vector<NavigationSample> Navigation(double rate_hz) const;

  const Scene& scene() const;
  // The scanner the dive was simulated with (see EffectiveScanner) and the scan pattern:
  // together, what reconstruction needs.
  const Scanner& scanner() const;
  ScanPattern scan_pattern() const;
  double frame_period_s() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace uwscan::scanner::sim
