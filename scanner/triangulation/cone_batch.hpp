#pragma once

#include <cstddef>

#include "scanner/triangulation/light_cone.hpp"

namespace uwscan::scanner {

// A block of rays in structure-of-arrays form: the layout the batched intersection needs so
// that the compiler can process several rays per instruction.
struct RayBlock {
  static constexpr std::size_t kSize = 16;
  double ox[kSize], oy[kSize], oz[kSize];  // origins, camera frame {C}
  double dx[kSize], dy[kSize], dz[kSize];  // directions (any length)
};

// Hits of a block: status, ray parameter and point in {C}.
struct HitBlock {
  double status[RayBlock::kSize];  // a HitStatus value, kept as double for the vector lanes
  HitStatus Status(std::size_t lane) const { return static_cast<HitStatus>(status[lane]); }
  double t[RayBlock::kSize];
  double x[RayBlock::kSize], y[RayBlock::kSize], z[RayBlock::kSize];
};

// IntersectRayCone (light_cone.hpp) for every ray of a block, the same method, tests and
// statuses, written without branches over structure-of-arrays data so that it runs several
// rays per vector instruction (AVX-512 or AVX2 where the CPU has them, chosen at run time; results
// do not depend on which: the same IEEE operations in the same order, no fused multiply-add).
// Then every hit whose ray meets the cone at an angle whose squared sine is at most
// min_sin2_angle becomes kParallel: the angle between the ray and the cone's tangent plane at
// the crossing, the test ray-plane makes against its plane (0 rejects only rays along it).
// Misses get t = 0 and the point (0, 0, 0); a ray of zero direction is a kParallel miss. Every
// lane must hold a finite ray (fill unused lanes with any). Agreement with the per-ray function
// is checked in cone_batch_test.
void IntersectRayConeBlock(const PreparedCone& cone, const RayBlock& rays, double min_sin2_angle,
                           HitBlock* hits);

}  // namespace uwscan::scanner
