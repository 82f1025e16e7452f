#include "scanner/acquisition/mirror_driver.hpp"

namespace uwscan::scanner::acquisition {

SimulatedMirrorDriver::SimulatedMirrorDriver(const ScanPattern& pattern) : pattern_(pattern) {
  pattern_.Check();
}

MirrorCommand SimulatedMirrorDriver::CommandOf(std::uint64_t index) const {
  const auto per_sweep = static_cast<std::uint64_t>(pattern_.frames_per_sweep());
  const int in_sweep = static_cast<int>(index % per_sweep);
  MirrorCommand c;
  c.sweep = static_cast<int>(index / per_sweep);
  c.command =
      pattern_.kind == ScannerKind::kGalvo ? pattern_.galvo.StepOfFrame(in_sweep) : in_sweep;
  return c;
}

MirrorCommand SimulatedMirrorDriver::OnTrigger(std::uint64_t trigger_index) {
  ++triggers_;
  return CommandOf(trigger_index);
}

double SimulatedMirrorDriver::trigger_rate_hz() const {
  if (pattern_.kind == ScannerKind::kGalvo) return pattern_.galvo.frame_rate_hz;
  return pattern_.mems.waypoint_rate_hz / pattern_.mems.waypoints_per_line;
}

}  // namespace uwscan::scanner::acquisition
