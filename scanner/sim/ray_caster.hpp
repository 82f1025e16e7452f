#pragma once

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "scanner/optics/ray.hpp"
#include "scanner/sim/scene.hpp"

namespace uwscan::scanner::sim {

// The first surface a ray meets.
struct SurfaceHit {
  double distance_m = 0.0;  // from the ray origin, metres
  Eigen::Vector3d point_W = Eigen::Vector3d::Zero();
  // Unit normal of the surface at the point, pointing out of the object (as the mesh is
  // oriented; +z_O for a plane): it may face away from the ray.
  Eigen::Vector3d normal_W = Eigen::Vector3d::UnitZ();
  int object_index = -1;  // into the objects the caster was built from
  double reflectance = 0.0;
};

// Ray casting against a scene's objects, in the world frame {W}: Embree finds the candidate
// surfaces in single precision, and every candidate is then re-intersected in double (the
// triangle Embree reports by Moller-Trumbore, spheres analytically), so both the range test
// and the returned hit are exact to double precision, whatever Embree's rounding. Embree works
// relative to the centre of the objects' bounds, so world coordinates far from the origin lose
// nothing either.
//
// Triangles are two-sided. Cast and Blocked may be called concurrently from any number of
// threads. Movable, not copyable.
class RayCaster {
 public:
  // Objects are posed by their T_W_O; the caster keeps its own copy of their geometry. Throws
  // uwscan::Error when an object has no geometry (no triangles, or a sphere of radius <= 0),
  // a triangle indexes a missing vertex, or Embree cannot build the scene.
  explicit RayCaster(const std::vector<SceneObject>& objects);
  ~RayCaster();
  RayCaster(RayCaster&&) noexcept;
  RayCaster& operator=(RayCaster&&) noexcept;

  // The first surface on origin + t * direction with the metric distance t * |direction| in
  // (t_min_m, t_max_m]. The direction need not be unit length. A ray that starts on a surface
  // finds that surface at distance ~0 unless t_min_m excludes it (a few nanometres suffice:
  // distances are exact in double). std::nullopt when nothing lies in range. Throws
  // uwscan::Error when the ray is not finite, its direction is zero, or t_min_m < 0.
  std::optional<SurfaceHit> Cast(const Ray& ray_W, double t_min_m = 0.0,
                                 double t_max_m = std::numeric_limits<double>::infinity()) const;

  // True when a surface lies strictly between from_W and to_W, more than eps_m from either end
  // (so the surfaces the two points sit on do not count). A segment no longer than 2 eps_m is
  // never blocked.
  bool Blocked(const Eigen::Vector3d& from_W, const Eigen::Vector3d& to_W,
               double eps_m = 1e-6) const;

  // Distance from p_W to the nearest surface of the scene (triangles and spheres, exact in
  // double), when one lies within max_m; std::nullopt otherwise. Thread-safe like Cast. Throws
  // uwscan::Error when p_W is not finite or max_m is not > 0.
  std::optional<double> DistanceToSurface(const Eigen::Vector3d& p_W, double max_m) const;

  int object_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace uwscan::scanner::sim
