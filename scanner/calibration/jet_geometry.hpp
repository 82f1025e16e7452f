#pragma once

// Geometry written for Ceres Jets (values that carry derivatives), shared by the calibration
// refinements. Included by .cpp files only: it pulls in Ceres.

#include <ceres/jet.h>

#include <Eigen/Core>
#include <cmath>

#include "scanner/optics/flat_viewport.hpp"

namespace uwscan::scanner::calibration::jet {

template <typename T>
using Vec3 = Eigen::Matrix<T, 3, 1>;

// The value part of a number that may be a Jet.
inline double Value(double x) { return x; }
template <int N>
double Value(const ceres::Jet<double, N>& x) {
  return x.a;
}

// A flat viewport whose geometry may carry Jets (its refractive indices are known).
template <typename T>
struct Slab {
  Vec3<T> normal;  // unit
  T distance_m;
  T thickness_m;
};

// TraceOut's closed form (air -> glass -> water through parallel faces) for Jets, the ray taken
// as a line (no check that the faces lie ahead): out_origin on the outer face.
template <typename T>
void TraceOutT(const Slab<T>& slab, const FlatViewport& indices, const Vec3<T>& origin,
               const Vec3<T>& direction, Vec3<T>& out_origin, Vec3<T>& out_direction) {
  using std::sqrt;
  const Vec3<T>& n = slab.normal;
  const T cos_air = n.dot(direction);
  const T t = (slab.distance_m - n.dot(origin)) / cos_air;
  const Vec3<T> along_faces = direction - cos_air * n;
  const T sin2_air = along_faces.squaredNorm();
  const double eta_glass = indices.n_air / indices.n_glass;
  const double eta_water = indices.n_air / indices.n_water;
  const T cos_glass = sqrt(T(1.0) - eta_glass * eta_glass * sin2_air);
  const T cos_water = sqrt(T(1.0) - eta_water * eta_water * sin2_air);
  out_origin =
      origin + t * direction + slab.thickness_m * ((eta_glass / cos_glass) * along_faces + n);
  out_direction = eta_water * along_faces + cos_water * n;
}

}  // namespace uwscan::scanner::calibration::jet
