#pragma once

// The seed's simplified galvanometer laser model (planes per mirror step, the laser plane,
// the mirror axis, the emitter from the fan's edge rays), the start of the full model's
// refinement in galvo_laser_calibration.cpp. Internal to calibration/.

#include <Eigen/Core>
#include <map>
#include <optional>
#include <vector>

#include "scanner/calibration/laser_points.hpp"
#include "scanner/lasers/galvo_laser.hpp"

namespace uwscan::scanner::calibration::galvo_simplified {

using PointsByStep = std::map<int, std::vector<const LaserCalibrationPoint*>>;

PointsByStep GroupBySteps(const std::vector<LaserCalibrationPoint>& points);

// The lasers are traced in air here: the water side of the viewport is air.
GalvoLaser InAir(GalvoLaser laser);

struct Simplified {
  GalvoLaser laser;
  bool emitter_from_edge_rays = false;
};

// SimplifiedGalvoLaser (galvo_laser_calibration.hpp) on points grouped by step, in air.
Simplified SimplifiedModel(const PointsByStep& by_step, const GalvoLaser& initial);

// The seed's estimate of the emitter: on every projection plane a stripe that reaches the
// fan's edges ends on the two edge rays, so each step's stripe ends, over the planes, lie on
// two lines; traced back in through the viewport and reflected on the mirror plane they pass
// through the emitter. Their point closest to all of them on pi_l (z_L = n_l, offset_l) is
// the emitter. A stripe cut short (by the image, or the board's border) ends elsewhere: then
// the angle between its step's two lines is not the aperture, and that step is not used.
// std::nullopt when no step qualifies or the lines do not meet (rms gap above 2 mm).
std::optional<Eigen::Vector3d> EmitterFromEdgeRays(const PointsByStep& by_step,
                                                   const GalvoLaser& laser, double offset_l);

}  // namespace uwscan::scanner::calibration::galvo_simplified
