#pragma once

#include <vector>

#include "scanner/lasers/galvo_laser.hpp"
#include "scanner/triangulation/cone_fit.hpp"
#include "scanner/triangulation/light_cone.hpp"
#include "scanner/triangulation/light_plane.hpp"

namespace uwscan::scanner {

// How the light surface of each mirror step is sampled before fitting: fan rays traced into
// the water and cut at camera depths spanning the working range.
struct LightSurfaceTableOptions {
  double depth_min_m = 0.4;  // camera-frame z of the nearest samples
  double depth_max_m = 1.6;  // ... and of the farthest
  int rays_per_fan = 35;     // seed: 35 model rays
  int points_per_ray = 5;    // seed: 5 points per ray
  bool fit_cones =
      true;  // false: planes only (all ray-plane needs; the cone fits are ~all the cost)
  ConeFitOptions cone;

  void Check() const;
};

// The plane and the elliptic cone fitted to one mirror step's light surface in water (the cone
// left default, cone_converged false, when the table fits no cones).
struct LightSurfaces {
  Plane plane;
  EllipticCone cone;
  double plane_rms_m = 0.0;
  double cone_rms_m = 0.0;
  bool cone_converged = false;
};

// Sampled points of one fan in water, plus the hints the cone fit starts from.
struct FanSamples {
  std::vector<Eigen::Vector3d> points_C;
  Eigen::Vector3d propagation_dir_C;  // central ray in water
  Eigen::Vector3d apex_hint_C;        // where the central ray leaves the mirror
};
// Throws uwscan::Error if the central ray does not reach the water or too few samples do.
FanSamples SampleFan(const LaserFan& fan, double max_fan_tan,
                     const LightSurfaceTableOptions& options);

// Plane and cone per mirror step, fitted once per calibration (steps in parallel; each fit is
// deterministic, so the table does not depend on the thread count).
class LightSurfaceTable {
 public:
  LightSurfaceTable(const GalvoLaser& laser, const LightSurfaceTableOptions& options);
  // A table computed before (light_surface_cache.hpp): surfaces[i] is step step_min + i.
  LightSurfaceTable(int step_min, std::vector<LightSurfaces> surfaces, bool has_cones);

  // nullptr when the step lies outside the laser's command range.
  const LightSurfaces* At(int step) const {
    if (step < step_min_ || step > step_max_) return nullptr;
    return &surfaces_[static_cast<size_t>(step - step_min_)];
  }
  int step_min() const { return step_min_; }
  int step_max() const { return step_max_; }
  bool has_cones() const { return has_cones_; }
  const std::vector<LightSurfaces>& surfaces() const { return surfaces_; }

 private:
  int step_min_;
  int step_max_;
  std::vector<LightSurfaces> surfaces_;
  bool has_cones_ = true;
};

}  // namespace uwscan::scanner
