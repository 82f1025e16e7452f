#include "scanner/sim/effects.hpp"

#include <utility>

#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner::sim {

// Values are checked whether or not their stage is on: a scene that switches a stage on later
// must not discover then that its numbers were never usable.
void SimulationEffects::Check() const {
  const OptionChecks check("SimulationEffects");
  const NavigationDrift& drift = navigation_drift;
  check.NonNegative("navigation_drift.position_walk_m_per_sqrt_s", drift.position_walk_m_per_sqrt_s,
                    "m/sqrt(s)");
  check.NonNegative("navigation_drift.yaw_walk_rad_per_sqrt_s", drift.yaw_walk_rad_per_sqrt_s,
                    "rad/sqrt(s)");
  check.InRange("navigation_drift.speed_scale_sigma", drift.speed_scale_sigma, 0.0, 0.5,
                Interval::kOpenHigh);
  check.NonNegative("navigation_drift.heading_bias_sigma_rad", drift.heading_bias_sigma_rad, "rad");
  check.NonNegative("navigation_drift.depth_sigma_m", drift.depth_sigma_m, "m");
  check.NonNegative("navigation_drift.roll_pitch_sigma_rad", drift.roll_pitch_sigma_rad, "rad");
  check.NonNegative("peak_noise.sigma_px", peak_noise.sigma_px, "px");
  check.Require(image.format == PixelFormat::kMono8 || image.format == PixelFormat::kMono16,
                "image.format", "mono8 or mono16", static_cast<int>(image.format));
  // A peak above the format's maximum is allowed: it simulates a saturated stripe.
  check.Positive("image.peak_level", image.peak_level, "image units");
  check.Positive("image.blur_sigma_px", image.blur_sigma_px, "px");
  check.Positive("beam.diameter_m", beam.diameter_m, "m");
  check.InRange("beam.divergence_rad", beam.divergence_rad, 0.0, 0.1, Interval::kOpenHigh,
                "rad (full angle)");
  check.NonNegative("sensor_noise.read_sigma", sensor_noise.read_sigma, "image units");
  check.Positive("sensor_noise.electrons_per_level", sensor_noise.electrons_per_level);
  check.InRange("speckle.contrast", speckle.contrast, 0.0, 1.0);
  check.NonNegative("backscatter.level", backscatter.level, "image units");
  check.NonNegative("ambient.level", ambient.level, "image units");
}

SimulationEffects RealisticImageEffects(bool underwater, SimulationEffects base) {
  SimulationEffects e = base;
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
