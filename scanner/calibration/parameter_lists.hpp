#pragma once

#include <string>
#include <vector>

#include "scanner/calibration/calibration_file.hpp"
#include "scanner/calibration/galvo_laser_calibration.hpp"
#include "scanner/calibration/intrinsics_calibration.hpp"
#include "scanner/optics/flat_viewport.hpp"
#include "scanner/optics/pinhole_camera.hpp"

namespace uwscan::scanner::calibration {

// The named parameters a calibration step records, from a model (and, for an estimate, its
// standard deviations; 0 where none). The same names for an estimate and for the truth, so that
// the calibration benchmark compares them one to one.

std::vector<ParameterEstimate> CameraParameters(const PinholeCamera& camera,
                                                const IntrinsicsResult* stds = nullptr);

struct ViewportStds {
  double normal_rad = 0.0;
  double distance_m = 0.0;
  double thickness_m = 0.0;
};
std::vector<ParameterEstimate> ViewportParameters(const std::string& key,
                                                  const FlatViewport& viewport,
                                                  const ViewportStds& stds = {});

// In the camera frame: emitter position, laser-plane normal (z_L), mirror position and axis (y_M),
// mirror step and rotation distance. Standard deviations given in the laser's and the mirror's
// own axes are carried to camera-frame components (independent axes assumed).
std::vector<ParameterEstimate> GalvoLaserParameters(const GalvoLaser& laser,
                                                    const GalvoLaserStdDevs* stds = nullptr);

}  // namespace uwscan::scanner::calibration
