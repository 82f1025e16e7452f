#include "scanner/sim/depth_camera.hpp"

#include <cmath>
#include <numbers>

#include "scanner/common/option_checks.hpp"
#include "scanner/sim/ray_caster.hpp"

namespace uwscan::scanner::sim {
namespace {

// SplitMix64's output function (Steele, Lea and Flood 2014): well mixed bits from a counter.
std::uint64_t Mix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

// A standard normal draw of its own for each (seed, pixel), by Box-Muller from two uniforms in
// (0, 1]: a pixel's noise does not depend on which pixels were drawn before it.
double PixelNormal(std::uint64_t seed, std::uint64_t pixel) {
  const std::uint64_t a = Mix(Mix(seed) ^ (2 * pixel));
  const std::uint64_t b = Mix(Mix(seed) ^ (2 * pixel + 1));
  const double u1 = (static_cast<double>(a >> 11) + 1.0) * 0x1.0p-53;
  const double u2 = static_cast<double>(b >> 11) * 0x1.0p-53;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

// The ray of pixel (u, v) in {C}, its z component 1: the pixel's centre through a pinhole with
// the principal point at the image centre.
Eigen::Vector3d PixelRay(int u, int v, const DepthCameraOptions& o) {
  const double focal_px = 0.5 * o.width_px / std::tan(0.5 * o.horizontal_fov_rad);
  return {(u + 0.5 - 0.5 * o.width_px) / focal_px, (v + 0.5 - 0.5 * o.height_px) / focal_px, 1.0};
}

}  // namespace

void DepthCameraOptions::Check() const {
  const OptionChecks check("DepthCameraOptions");
  check.AtLeast("width_px", width_px, 2);
  check.AtLeast("height_px", height_px, 2);
  check.InRange("horizontal_fov_rad", horizontal_fov_rad, 0.0, std::numbers::pi, Interval::kOpen,
                "rad");
  check.Positive("min_range_m", min_range_m, "m");
  check.GreaterThan("max_range_m", max_range_m, min_range_m, "m");
  check.NonNegative("noise_per_m", noise_per_m, "1/m");
}

DepthScan ScanWithDepthCamera(const std::vector<SceneObject>& objects,
                              const Eigen::Isometry3d& T_W_C, const DepthCameraOptions& options,
                              std::uint64_t seed) {
  options.Check();
  const RayCaster caster(objects);
  DepthScan scan;
  for (int v = 0; v < options.height_px; ++v) {
    for (int u = 0; u < options.width_px; ++u) {
      const Eigen::Vector3d ray_C = PixelRay(u, v, options);
      const std::optional<SurfaceHit> hit =
          caster.Cast({T_W_C.translation(), T_W_C.linear() * ray_C});
      if (!hit) continue;
      const double depth_m = (T_W_C.inverse() * hit->point_W).z();
      if (depth_m < options.min_range_m || depth_m > options.max_range_m) continue;
      const double noise_m =
          options.noise_per_m * depth_m * depth_m *
          PixelNormal(seed, static_cast<std::uint64_t>(v) * options.width_px + u);
      scan.points_C.push_back((depth_m + noise_m) * ray_C);
      scan.object_index.push_back(hit->object_index);
    }
  }
  return scan;
}

}  // namespace uwscan::scanner::sim
