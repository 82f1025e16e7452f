#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <vector>

#include "scanner/optics/flat_viewport.hpp"
#include "scanner/optics/refractive_camera.hpp"
#include "scanner/sim/ray_caster.hpp"
#include "scanner/stripe/stripe_detector.hpp"

namespace uwscan::scanner::sim {

// The light of one frame as a one-parameter family of laser rays in water, in {C}: the fan of
// a galvanometer step (s = fan tangent) or the dot path of a MEMS line (s = time).
struct LaserPath {
  std::function<RayTrace(double s)> ray_in_water_C;
  double s_begin = 0.0;
  double s_end = 1.0;
  int samples = 513;  // initial sampling; crossings between samples are solved exactly
};

struct StripeTraceOptions {
  StripeAxis axis = StripeAxis::kRows;  // kRows: one peak where the stripe crosses a row centre
  bool occlusion = true;      // drop spots hidden from the camera (by other objects or back faces)
  double max_jump_px = 25.0;  // neighbouring samples farther apart belong to different surfaces
};

// One exact stripe peak: where the image of the lit surface crosses a row (or column) centre,
// with what the image stages need to render it.
struct TracedPeak {
  Eigen::Vector2d px;        // pixel; px.y() (kRows) is an integer row
  Eigen::Vector3d p_W;       // lit surface point, world frame
  Eigen::Vector3d normal_W;  // surface normal there
  int object_index = -1;
  double reflectance = 0.0;
  double laser_range_m = 0.0;   // laser ray in water, viewport to the spot
  double camera_range_m = 0.0;  // spot to the camera viewport
  double cos_incidence = 1.0;   // laser ray against the surface normal
  double z_C_m = 0.0;           // depth of the spot in the camera frame
  double s = 0.0;               // path parameter
};

// Finds every crossing of the stripe's image with a row (or column) centre: the path is sampled,
// where two neighbouring samples do not continue each other (a miss, another surface, a jump)
// the interval is halved until every part is continuous or ends at an edge, and each crossing
// between two spots on
// the same surface is solved for by a safeguarded
// secant search on s to 1e-9 px, each evaluation an exact ray cast and an exact projection
// through the camera viewport. Deterministic; safe to call from several threads.
class StripeTracer {
 public:
  StripeTracer(const RefractiveCamera& camera, const RayCaster& caster,
               const StripeTraceOptions& options);

  std::vector<TracedPeak> Trace(const LaserPath& path, const Eigen::Isometry3d& T_W_C) const;

  // The laser spot of path parameter s, as the camera sees it (std::nullopt: no spot, or one
  // the camera cannot image). Exposed for the image stages and tests.
  std::optional<TracedPeak> SpotAt(const LaserPath& path, const Eigen::Isometry3d& T_W_C,
                                   double s) const;

 private:
  bool Visible(const TracedPeak& spot, const Eigen::Vector3d& laser_origin_W,
               const Eigen::Vector3d& camera_exit_W) const;
  bool Continues(const TracedPeak& a, const TracedPeak& b) const;
  void Follow(const LaserPath& path, const Eigen::Isometry3d& T_W_C, double s_a,
              const std::optional<TracedPeak>& a, double s_b, const std::optional<TracedPeak>& b,
              int depth, std::vector<TracedPeak>* peaks) const;
  void AddCrossings(const LaserPath& path, const Eigen::Isometry3d& T_W_C, const TracedPeak& a,
                    const TracedPeak& b, std::vector<TracedPeak>* peaks) const;
  std::optional<TracedPeak> SolveCrossing(const LaserPath& path, const Eigen::Isometry3d& T_W_C,
                                          const TracedPeak& a, const TracedPeak& b,
                                          double line) const;

  RefractiveCamera camera_;
  const RayCaster& caster_;
  StripeTraceOptions options_;
  double max_normalised_radius2_;  // beyond it the distortion polynomial is not trusted
};

}  // namespace uwscan::scanner::sim
