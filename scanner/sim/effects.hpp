#pragma once

#include "scanner/stripe/stripe_image.hpp"

namespace uwscan::scanner::sim {

// The simulation effects a scene calls for (DESIGN.md, "only the effects a scene calls for").
// Each is a separate stage of the simulator; a stage that is off is skipped, so it costs
// nothing and changes nothing. With every image stage off the simulator emits the exact
// stripe peaks; with any image stage on it renders frames and detects the stripe in them.
struct SimulationEffects {
  // --- Geometry: where the stripe falls ---------------------------------------------------
  bool refraction = true;       // viewports bend rays; off: both viewports are taken away
  bool lens_distortion = true;  // off: the camera's distortion coefficients are zeroed
  bool occlusion = true;        // a laser spot the camera cannot see gives no peak
  bool mirror_dynamics = false; // MEMS: low-pass filter + resonant mirror between waypoints
  bool motion = false;          // the vehicle moves during a sweep: each frame at its own pose

  // Navigation the vehicle believes in: the true trajectory plus a random walk.
  struct NavigationDrift {
    bool on = false;
    double position_walk_m_per_sqrt_s = 0.002;  // random-walk density of x, y, z
    double yaw_walk_rad_per_sqrt_s = 0.0005;    // random-walk density of the heading
  } navigation_drift;

  // --- Image: how the stripe looks (any of these on => frames are rendered) ---------------
  struct Image {
    bool on = false;
    PixelFormat format = PixelFormat::kMono8;
    double peak_level = 180.0;  // stripe peak, image units, white target at 1 m, clear water
    double blur_sigma_px = 0.7; // optics and pixel blur; the stripe is never narrower
  } image;
  struct Beam {  // stripe width from the beam's footprint (seed 001 laser: 1 mm, 1.1 mrad)
    bool on = false;
    double diameter_m = 0.001;
    double divergence_rad = 0.0011;  // full angle
  } beam;
  struct SensorNoise {
    bool on = false;
    double read_sigma = 1.0;        // read noise, image units
    double electrons_per_level = 4; // shot noise: variance = level / electrons_per_level
  } sensor_noise;
  struct Speckle {
    bool on = false;
    double contrast = 0.15;  // std / mean of the multiplicative speckle along the stripe
  } speckle;
  bool attenuation = false;  // exp(-c (laser path + camera path)) with the water's c
  struct Backscatter {
    bool on = false;
    double level = 12.0;  // glow of the beam in water seen by the camera, image units at 1 m
  } backscatter;
  struct Ambient {
    bool on = false;
    double level = 8.0;  // uniform ambient light, image units
  } ambient;

  bool AnyImageStage() const {
    return image.on || beam.on || sensor_noise.on || speckle.on || attenuation ||
           backscatter.on || ambient.on;
  }
  // Throws uwscan::Error naming the field when a value is unusable.
  void Check() const;
};

}  // namespace uwscan::scanner::sim
