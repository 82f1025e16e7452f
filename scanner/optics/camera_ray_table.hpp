#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "scanner/optics/ray.hpp"
#include "scanner/optics/refractive_camera.hpp"

namespace uwscan::scanner {

// Camera rays in water precomputed on a regular pixel grid and interpolated bilinearly, so
// the fast triangulators pay neither the iterative undistortion nor the two refractions per
// point. Built once per calibration. Both the ray origins (on the flat outer face) and the
// directions vary smoothly with the pixel, so with the default 4 px grid the interpolated
// direction stays within 1e-6 rad (0.7 um at 1.5 m) of the exact one (tested in
// triangulation_test, CameraRayTableMatchesExactRays).
class CameraRayTable {
 public:
  // Throws uwscan::Error if grid_px < 1 or some grid node has no ray (distortion folding over
  // inside the image).
  CameraRayTable(const RefractiveCamera& camera, int grid_px = 4);

  struct Node {  // the ray at a grid point
    double origin[3];
    double direction[3];
  };

  // The table as plain values, for loops that store doubles between lookups. Copied into a
  // local, its fields stay in registers; read through the table they are loaded again after
  // every such store, which the compiler cannot tell from the nodes (bench/scanner/RESULTS.md,
  // "The limit was about an eighth too slow"). Valid while the table lives.
  class Grid {
   public:
    // Ray in water for a pixel inside the image (OpenCV pixel convention). The direction is
    // interpolated, hence close to but not exactly unit length. False outside the image.
    bool Lookup(double u_px, double v_px, Ray* ray) const {
      const double fu = (u_px + 0.5) * inverse_grid_;
      const double fv = (v_px + 0.5) * inverse_grid_;
      if (!(fu >= 0.0 && fv >= 0.0 && fu < max_u_ && fv < max_v_)) return false;
      const int iu = static_cast<int>(fu);
      const int iv = static_cast<int>(fv);
      const double wu = fu - iu, wv = fv - iv;
      const Node& n00 = nodes_[static_cast<size_t>(iv) * columns_ + iu];
      const Node& n01 = (&n00)[1];
      const Node& n10 = (&n00)[columns_];
      const Node& n11 = (&n10)[1];
      const double w00 = (1.0 - wu) * (1.0 - wv), w01 = wu * (1.0 - wv);
      const double w10 = (1.0 - wu) * wv, w11 = wu * wv;
      for (int k = 0; k < 3; ++k) {
        ray->origin[k] =
            w00 * n00.origin[k] + w01 * n01.origin[k] + w10 * n10.origin[k] + w11 * n11.origin[k];
        ray->direction[k] = w00 * n00.direction[k] + w01 * n01.direction[k] +
                            w10 * n10.direction[k] + w11 * n11.direction[k];
      }
      return true;
    }

    // Hints the cache to fetch the nodes a later Lookup of this pixel reads. Stripe peaks come
    // one per image row, so consecutive lookups land in different table rows and would each
    // wait on memory; prefetching a few peaks ahead hides that latency. Safe for any pixel.
    void Prefetch(double u_px, double v_px) const {
      const double fu = (u_px + 0.5) * inverse_grid_;
      const double fv = (v_px + 0.5) * inverse_grid_;
      if (!(fu >= 0.0 && fv >= 0.0 && fu < max_u_ && fv < max_v_)) return;
      const Node* n00 = &nodes_[static_cast<size_t>(fv) * columns_ + static_cast<size_t>(fu)];
      __builtin_prefetch(n00);
      __builtin_prefetch(reinterpret_cast<const char*>(n00 + 2) - 1);
      __builtin_prefetch(n00 + columns_);
      __builtin_prefetch(reinterpret_cast<const char*>(n00 + columns_ + 2) - 1);
    }

   private:
    friend class CameraRayTable;
    const Node* nodes_ = nullptr;
    double inverse_grid_ = 0.0;
    std::size_t columns_ = 0;
    double max_u_ = 0.0;  // interpolation domain in grid units
    double max_v_ = 0.0;
  };

  Grid grid() const {
    Grid g;
    g.nodes_ = nodes_.data();
    g.inverse_grid_ = inverse_grid_;
    g.columns_ = static_cast<std::size_t>(columns_);
    g.max_u_ = max_u_;
    g.max_v_ = max_v_;
    return g;
  }

  // Grid::Lookup and Grid::Prefetch, for callers outside a hot loop.
  bool Lookup(double u_px, double v_px, Ray* ray) const { return grid().Lookup(u_px, v_px, ray); }
  void Prefetch(double u_px, double v_px) const { grid().Prefetch(u_px, v_px); }

  // How many peaks ahead callers prefetch: far enough to cover a memory fetch, near enough that
  // the lines are still in cache when the lookup comes.
  static constexpr std::size_t kPrefetchAhead = 8;

  int grid_px() const { return grid_px_; }

 private:
  int grid_px_;
  double inverse_grid_;
  int columns_;
  int rows_;
  double max_u_;  // interpolation domain in grid units
  double max_v_;
  std::vector<Node> nodes_;
};

}  // namespace uwscan::scanner
