#pragma once

#include <memory>

#include "scanner/lasers/galvo_scanner_model.hpp"
#include "scanner/lasers/mems_scanner_model.hpp"
#include "scanner/lasers/scan_pattern.hpp"
#include "scanner/optics/refractive_camera.hpp"
#include "scanner/sim/stripe_tracer.hpp"

namespace uwscan::scanner::sim {

// A scanner as the simulator drives it: its camera, and for each frame of a sweep the mirror
// command and the light the camera integrates during the exposure.
class LightSource {
 public:
  virtual ~LightSource() = default;
  virtual const RefractiveCamera& camera() const = 0;
  virtual int frames_per_sweep() const = 0;
  virtual double frame_period_s() const = 0;
  virtual int CommandOfFrame(int frame_in_sweep) const = 0;
  // The laser rays lit during the frame, in {C}.
  virtual LaserPath PathOfFrame(int frame_in_sweep) const = 0;
};

// The galvanometer scanner `model` (seed 000) swept as `scan` says.
std::unique_ptr<LightSource> MakeGalvoLightSource(const GalvoScannerModel& model,
                                                  const GalvoScan& scan);

// The MEMS scanner `model` (seed 001) drawing the scan pattern `scan`, its mirror
// following the ideal path between waypoints or, with `mirror_dynamics`, its filtered and
// resonant response.
std::unique_ptr<LightSource> MakeMemsLightSource(const MemsScannerModel& model,
                                                 const MemsScan& scan, bool mirror_dynamics);

}  // namespace uwscan::scanner::sim
