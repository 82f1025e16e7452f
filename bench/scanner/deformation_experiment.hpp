#pragma once

#include <vector>

#include "bench/progress.hpp"
#include "scanner/triangulation/cone_fit.hpp"

namespace uwscan::bench {

// The seed's synthetic deformation experiment (seed 000, "Deformation model"): a laser fan of
// `rays` rays over `aperture_rad`, tilted so that its central ray meets a flat viewport at a
// given incidence angle, refracted air -> glass -> water; each ray cut by `points_per_ray`
// planes parallel to the viewport, `point_spacing_m` apart, the farthest at
// `projection_distance_m` from the outer face. A plane (SVD) and an elliptic cone (Ceres) are
// fitted to the points; their RMS orthogonal residuals show how far from a plane the light
// surface bends.
struct DeformationOptions {
  int rays = 35;
  double aperture_rad = 0.9599310885968813;  // 55 degrees
  double n_air = 1.0, n_glass = 1.49, n_water = 1.33;
  int points_per_ray = 5;
  double point_spacing_m = 0.100;
  double projection_distance_m = 1.5;
  int incidence_angles = 21;
  double max_incidence_rad = 0.3839724354387525;  // 22 degrees
  double source_to_viewport_m = 0.05;             // fan apex to the inner face
  double thickness_m = 0.015;
  scanner::ConeFitOptions cone;

  void Check() const;
};

struct DeformationRow {
  double incidence_rad = 0.0;
  double plane_rms_m = 0.0;
  double cone_rms_m = 0.0;
  bool cone_converged = false;
};

std::vector<DeformationRow> RunDeformationExperiment(const DeformationOptions& options,
                                                     const Progress& progress = {});

}  // namespace uwscan::bench
