#pragma once

#include <Eigen/Core>
#include <cmath>
#include <optional>

namespace uwscan::scanner {

// Mirror reflection of direction d on a surface with unit normal n (either orientation):
// r = d - 2 (d . n) n.
inline Eigen::Vector3d Reflect(const Eigen::Vector3d& d, const Eigen::Vector3d& n) {
  return d - 2.0 * d.dot(n) * n;
}

// Vector form of Snell's law (n1 sin t1 = n2 sin t2) for a unit direction d crossing a surface
// with unit normal n (either orientation) from index n1 into index n2. Returns the unit
// refracted direction, or std::nullopt on total internal reflection (an expected outcome).
// A ray that grazes the surface exactly (d . n = 0) is returned unchanged when n1 = n2, and
// otherwise refracts to the critical direction or reflects totally, as Snell's law says.
inline std::optional<Eigen::Vector3d> Refract(const Eigen::Vector3d& d, const Eigen::Vector3d& n,
                                              double n1, double n2) {
  double cos_i = -d.dot(n);
  Eigen::Vector3d normal = n;
  if (cos_i < 0.0) {  // orient the normal against the incoming ray
    cos_i = -cos_i;
    normal = -n;
  }
  const double eta = n1 / n2;
  const double sin2_t = eta * eta * std::max(0.0, 1.0 - cos_i * cos_i);
  if (sin2_t > 1.0) return std::nullopt;
  const double cos_t = std::sqrt(1.0 - sin2_t);
  return (eta * d + (eta * cos_i - cos_t) * normal).normalized();
}

}  // namespace uwscan::scanner
