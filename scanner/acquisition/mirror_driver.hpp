#pragma once

#include <cstdint>

#include "scanner/lasers/scan_pattern.hpp"

namespace uwscan::scanner::acquisition {

// The mirror command a frame was exposed with.
struct MirrorCommand {
  int command = 0;  // galvo: mirror step; MEMS: line index in the scan pattern
  int sweep = 0;    // which sweep of the scan pattern
};

// The hardware that moves the mirror in step with the camera (seed 001: a microcontroller
// that drives the MEMS mirror and triggers the camera). On each camera trigger it moves the
// mirror to the next command of its scan pattern and reports which command that frame sees.
class MirrorDriver {
 public:
  virtual ~MirrorDriver() = default;
  // Called once per camera trigger, trigger_index 0 first; returns the command in force for
  // that frame. Triggers come in order, one thread at a time.
  virtual MirrorCommand OnTrigger(std::uint64_t trigger_index) = 0;
  // The rate at which it triggers the camera, frames per second.
  virtual double trigger_rate_hz() const = 0;
};

// A mirror driver without hardware: it walks the scan pattern (galvo steps from step_min to
// step_max every step_stride, or MEMS lines 0..lines-1), one command per trigger, sweep after
// sweep, at the pattern's frame rate (galvo) or one line per waypoints_per_line waypoints
// (MEMS).
class SimulatedMirrorDriver : public MirrorDriver {
 public:
  // Throws uwscan::Error when the pattern fails its checks.
  explicit SimulatedMirrorDriver(const ScanPattern& pattern);
  MirrorCommand OnTrigger(std::uint64_t trigger_index) override;
  double trigger_rate_hz() const override;
  std::uint64_t triggers() const { return triggers_; }

  // The command of trigger `index` without moving anything.
  MirrorCommand CommandOf(std::uint64_t index) const;

 private:
  ScanPattern pattern_;
  std::uint64_t triggers_ = 0;
};

}  // namespace uwscan::scanner::acquisition
