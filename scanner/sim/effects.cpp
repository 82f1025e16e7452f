#include "scanner/sim/effects.hpp"

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::sim {
namespace {

// Throws "simulation effects: <field>: <value>, expected <what>" unless `ok`.
void Require(bool ok, const char* field, double value, const char* expected) {
  if (ok) return;
  char number[32];
  std::snprintf(number, sizeof(number), "%.9g", value);
  throw Error(std::string("simulation effects: ") + field + ": " + number + ", expected " +
              expected);
}

bool NonNegative(double v) { return std::isfinite(v) && v >= 0.0; }
bool Positive(double v) { return std::isfinite(v) && v > 0.0; }

}  // namespace

// Values are checked whether or not their stage is on: a scene that switches a stage on later
// must not discover then that its numbers were never usable.
void SimulationEffects::Check() const {
  Require(NonNegative(navigation_drift.position_walk_m_per_sqrt_s),
          "navigation_drift.position_walk_m_per_sqrt_s",
          navigation_drift.position_walk_m_per_sqrt_s, ">= 0 m/sqrt(s)");
  Require(NonNegative(navigation_drift.yaw_walk_rad_per_sqrt_s),
          "navigation_drift.yaw_walk_rad_per_sqrt_s", navigation_drift.yaw_walk_rad_per_sqrt_s,
          ">= 0 rad/sqrt(s)");
  Require(
      NonNegative(navigation_drift.speed_scale_sigma) && navigation_drift.speed_scale_sigma < 0.5,
      "navigation_drift.speed_scale_sigma", navigation_drift.speed_scale_sigma, "in [0, 0.5)");
  Require(NonNegative(navigation_drift.heading_bias_sigma_rad),
          "navigation_drift.heading_bias_sigma_rad", navigation_drift.heading_bias_sigma_rad,
          ">= 0 rad");
  Require(NonNegative(navigation_drift.depth_sigma_m), "navigation_drift.depth_sigma_m",
          navigation_drift.depth_sigma_m, ">= 0 m");
  Require(NonNegative(navigation_drift.roll_pitch_sigma_rad),
          "navigation_drift.roll_pitch_sigma_rad", navigation_drift.roll_pitch_sigma_rad,
          ">= 0 rad");
  Require(NonNegative(peak_noise.sigma_px), "peak_noise.sigma_px", peak_noise.sigma_px, ">= 0 px");
  if (image.format != PixelFormat::kMono8 && image.format != PixelFormat::kMono16) {
    throw Error("simulation effects: image.format: expected mono8 or mono16");
  }
  // A peak above the format's maximum is allowed: it simulates a saturated stripe.
  Require(Positive(image.peak_level), "image.peak_level", image.peak_level, "> 0 image units");
  Require(Positive(image.blur_sigma_px), "image.blur_sigma_px", image.blur_sigma_px, "> 0 px");
  Require(Positive(beam.diameter_m), "beam.diameter_m", beam.diameter_m, "> 0 m");
  Require(NonNegative(beam.divergence_rad) && beam.divergence_rad < 0.1, "beam.divergence_rad",
          beam.divergence_rad, "in [0, 0.1) rad (full angle)");
  Require(NonNegative(sensor_noise.read_sigma), "sensor_noise.read_sigma", sensor_noise.read_sigma,
          ">= 0 image units");
  Require(Positive(sensor_noise.electrons_per_level), "sensor_noise.electrons_per_level",
          sensor_noise.electrons_per_level, "> 0");
  Require(NonNegative(speckle.contrast) && speckle.contrast <= 1.0, "speckle.contrast",
          speckle.contrast, "in [0, 1]");
  Require(NonNegative(backscatter.level), "backscatter.level", backscatter.level,
          ">= 0 image units");
  Require(NonNegative(ambient.level), "ambient.level", ambient.level, ">= 0 image units");
}

SimulationEffects RealisticImageEffects(bool underwater, SimulationEffects base) {
  SimulationEffects e = std::move(base);
  e.image.on = true;
  e.image.peak_level = 220.0;
  e.beam.on = true;
  e.sensor_noise.on = true;
  e.speckle.on = true;
  e.speckle.contrast = 0.3;
  e.ambient.on = true;
  e.attenuation = underwater;
  e.backscatter.on = underwater;
  return e;
}

}  // namespace uwscan::scanner::sim
