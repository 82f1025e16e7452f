#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/lasers/mems_scan_pattern.hpp"
#include "scanner/lasers/mems_scanner_model.hpp"
#include "scanner/lasers/mirror_dynamics.hpp"
#include "scanner/sim/light_source.hpp"

namespace uwscan::scanner::sim {
namespace {

// The tracer's first sampling of a line's dot path; crossings in between are solved exactly.
constexpr int kMinPathSamples = 513;

MirrorDynamicsOptions DynamicsOfScan(const MemsScannerModel& model, const MemsScan& scan) {
  // The scan pattern sets the DAC's waypoint rate; the mirror and its filter are the scanner's.
  scan.Check();  // a bad scene value is reported as the scene's, not as a mirror field
  MirrorDynamicsOptions dynamics = model.dynamics;
  dynamics.waypoint_rate_hz = scan.waypoint_rate_hz;
  dynamics.Check();
  return dynamics;
}

class MemsLightSource final : public LightSource {
 public:
  MemsLightSource(MemsScannerModel model, const MemsScan& scan, bool mirror_dynamics)
      : model_(std::move(model)),
        scan_(scan),
        dynamics_(DynamicsOfScan(model_, scan)),
        mirror_dynamics_(mirror_dynamics),
        lines_(DesignMemsScanPattern(model_.functions, PatternOptions(scan))) {}

  static MemsScanPatternOptions PatternOptions(const MemsScan& scan) {
    scan.Check();
    MemsScanPatternOptions o;
    o.lines = scan.lines;
    o.waypoints_per_line = scan.waypoints_per_line;
    o.fov_fraction_x = scan.fov_fraction_x;
    o.fov_fraction_y = scan.fov_fraction_y;
    return o;
  }

  const RefractiveCamera& camera() const override { return model_.camera; }
  int frames_per_sweep() const override { return static_cast<int>(lines_.size()); }
  double frame_period_s() const override {
    return 1.0 / LinesPerSecond(scan_.waypoints_per_line, dynamics_);
  }
  int CommandOfFrame(int frame_in_sweep) const override { return frame_in_sweep; }

  LaserPath PathOfFrame(int frame_in_sweep) const override {
    // The dot's path over the exposure: tilt samples of the mirror (ideal or dynamic),
    // interpolated linearly in between, then traced through lens and viewport.
    auto tilt = std::make_shared<const TiltPath>(
        SimulateLine(model_.laser, lines_.at(static_cast<size_t>(frame_in_sweep)).volts, dynamics_,
                     mirror_dynamics_));
    if (tilt->samples.size() < 2)
      throw Error("MEMS simulation: a line yielded fewer than 2 tilt samples");
    auto laser = std::make_shared<const MemsLaser>(model_.laser);
    LaserPath path;
    const double last = static_cast<double>(tilt->samples.size() - 1);
    path.ray_in_water_C = [tilt, laser, last](double s) {
      const double clamped = std::clamp(s, 0.0, last);
      const size_t k = std::min(static_cast<size_t>(clamped), tilt->samples.size() - 2);
      const double f = clamped - static_cast<double>(k);
      const Eigen::Vector2d t =
          (1.0 - f) * tilt->samples[k].tilt_rad + f * tilt->samples[k + 1].tilt_rad;
      return laser->RayInWaterFromTilt(t);
    };
    path.s_begin = 0.0;
    path.s_end = last;
    path.samples = std::max(kMinPathSamples, static_cast<int>(tilt->samples.size()));
    return path;
  }

 private:
  MemsScannerModel model_;
  MemsScan scan_;
  MirrorDynamicsOptions dynamics_;
  bool mirror_dynamics_;
  std::vector<MemsLine> lines_;
};

}  // namespace

std::unique_ptr<LightSource> MakeMemsLightSource(const MemsScannerModel& model,
                                                 const MemsScan& scan, bool mirror_dynamics) {
  return std::make_unique<MemsLightSource>(model, scan, mirror_dynamics);
}

}  // namespace uwscan::scanner::sim
