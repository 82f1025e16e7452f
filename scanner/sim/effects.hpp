#pragma once

#include "scanner/stripe/stripe_image.hpp"

namespace uwscan::scanner::sim {

// The simulation effects a scene calls for (DESIGN.md, "only the effects a scene calls for").
// Each is a separate stage of the simulator; a stage that is off is skipped, so it costs
// nothing and changes nothing. With every image stage off the simulator emits the exact
// stripe peaks; with any image stage on it renders frames and detects the stripe in them.
struct SimulationEffects {
  // --- Geometry: where the stripe falls ---------------------------------------------------
  bool refraction = true;        // viewports bend rays; off: both viewports are taken away
  bool lens_distortion = true;   // off: the camera's distortion coefficients are zeroed
  bool occlusion = true;         // a laser spot the camera cannot see gives no peak
  bool mirror_dynamics = false;  // MEMS: low-pass filter + resonant mirror between waypoints
  bool motion = false;           // the vehicle moves during a sweep: each frame at its own pose

  // Navigation the vehicle believes in, as a vehicle has it: depth (pressure sensor) and roll /
  // pitch (AHRS) absolute with white noise; x, y and heading by dead reckoning (DVL velocity
  // turned by the heading and integrated), which drifts: a random walk of position and heading,
  // a speed scale error and a heading bias, the DVL's misalignment, which turns the measured
  // velocity but not the reported heading (both drawn once per dive from the seed).
  struct NavigationDrift {
    bool on = false;
    double position_walk_m_per_sqrt_s = 0.002;  // random-walk density of x and y
    double yaw_walk_rad_per_sqrt_s = 0.0005;    // random-walk density of the heading
    double speed_scale_sigma = 0.0;             // std of the DVL's speed scale error (0.01 = 1 %)
    double heading_bias_sigma_rad = 0.0;        // std of the constant heading bias
    // Errors of the filtered absolute sensors: std of a slowly wandering error (correlation
    // time 5 s), not a jump per sample.
    double depth_sigma_m = 0.0;         // pressure depth
    double roll_pitch_sigma_rad = 0.0;  // AHRS roll and pitch
  } navigation_drift;

  // Exact peaks moved along their image line by Gaussian noise, for long dives where rendering
  // every frame would cost too much: the detector's error without the image. Ignored when an
  // image stage is on (the rendered frame then carries its own noise).
  struct PeakNoise {
    bool on = false;
    double sigma_px = 0.1;  // std of the sub-pixel position along the line
  } peak_noise;

  // --- Image: how the stripe looks (any of these on => frames are rendered) ---------------
  struct Image {
    bool on = false;
    PixelFormat format = PixelFormat::kMono8;
    double peak_level = 180.0;   // stripe peak, image units, white target at 1 m, clear water
    double blur_sigma_px = 0.7;  // optics and pixel blur; the stripe is never narrower
  } image;
  struct Beam {  // stripe width from the beam's footprint (seed 001 laser: 1 mm, 1.1 mrad)
    bool on = false;
    double diameter_m = 0.001;
    double divergence_rad = 0.0011;  // full angle
  } beam;
  struct SensorNoise {
    bool on = false;
    double read_sigma = 1.0;         // read noise, image units
    double electrons_per_level = 4;  // shot noise: variance = level / electrons_per_level
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
    return image.on || beam.on || sensor_noise.on || speckle.on || attenuation || backscatter.on ||
           ambient.on;
  }
  // Throws uwscan::Error naming the field when a value is unusable.
  void Check() const;
};

// The image stages a real dive's frames have (the seeds' accuracy experiments): stripes
// rendered at peak level 220 with the beam's footprint, speckle (contrast 0.3), shot and read
// noise and ambient light; under water also attenuation and backscatter. The other stages are
// base's.
SimulationEffects RealisticImageEffects(bool underwater, SimulationEffects base = {});

}  // namespace uwscan::scanner::sim
