#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "scanner/lasers/scan_pattern.hpp"
#include "scanner/lasers/scanner.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/triangulation/triangulator.hpp"

namespace uwscan::scanner::sim {

// The real scanner model as a headless range sensor: one sweep of the galvanometer or MEMS
// scanner over some objects, through both viewports, traced and (optionally) rendered and
// detected by the simulator, then triangulated as a dive log would be. Used to build object
// databases from meshes and to make recognition benchmarks.
struct VirtualScannerOptions {
  ScanPattern pattern;  // one sweep: the galvanometer steps or the MEMS lines
  Water water;          // 1.33 by default: the scanner under water
  // Refraction, distortion and occlusion, and the peaks moved by 0.1 px of noise (the default
  // peak_noise), without the cost of rendering every frame. The detector errs by more on
  // realistically rendered stripes (0.15-0.23 px, bench accuracy): turn image stages on to
  // render and detect frames instead, as bench recognition does by default.
  SimulationEffects effects = [] {
    SimulationEffects e;
    e.peak_noise.on = true;
    return e;
  }();
  // std::nullopt: the scanner's default (ray-cone for the galvanometer, ray-plane for MEMS).
  std::optional<TriangulationMethod> method;
  std::filesystem::path table_cache;  // folder keeping the cone table between runs (optional)
  // Throws uwscan::Error naming the field.
  void Check() const;
};

// A scan: points in the camera frame {C} with the true surface point and object of each.
struct VirtualScan {
  std::vector<Eigen::Vector3d> points_C;
  std::vector<Eigen::Vector3d> truth_C;    // NaN where the peak came from no lit point (noise)
  std::vector<std::int32_t> object_index;  // into the objects scanned, -1 for none
};

class VirtualScanner {
 public:
  // Builds the triangulator (tables) once. Throws uwscan::Error on invalid options or a
  // scanner of another kind than the pattern.
  VirtualScanner(const Scanner& scanner, const VirtualScannerOptions& options);
  ~VirtualScanner();
  VirtualScanner(const VirtualScanner&) = delete;
  VirtualScanner& operator=(const VirtualScanner&) = delete;

  // One sweep with the camera at T_W_C over `objects` (their poses in {W}). Deterministic in
  // `seed`; safe to call from several threads at once.
  VirtualScan Scan(const std::vector<SceneObject>& objects, const Eigen::Isometry3d& T_W_C,
                   std::uint64_t seed) const;

  // The scanner as simulated (scene water in the viewports; see EffectiveScanner).
  const Scanner& scanner() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The camera pose at eye_W looking at target_W (z forward), its image x axis (right) kept
// normal to up_W, so that -y (image up) leans towards up_W. Throws uwscan::Error when eye and
// target coincide or the view direction is parallel to up_W.
Eigen::Isometry3d LookAt(const Eigen::Vector3d& eye_W, const Eigen::Vector3d& target_W,
                         const Eigen::Vector3d& up_W);

// The camera at `standoff_m` from centre_W along the unit `direction`, looking at centre_W; up is
// +z unless the direction is within about 25 degrees of it (then +x).
Eigen::Isometry3d ViewFrom(const Eigen::Vector3d& centre_W, const Eigen::Vector3d& direction,
                           double standoff_m);

// `count` unit directions spread evenly over the sphere (a Fibonacci lattice), the first
// nearest +z. Throws uwscan::Error when count < 1.
std::vector<Eigen::Vector3d> SphereDirections(int count);

}  // namespace uwscan::scanner::sim
