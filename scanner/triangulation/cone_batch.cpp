#include "scanner/triangulation/cone_batch.hpp"

#include <cmath>
#include <limits>

namespace uwscan::scanner {
namespace {

constexpr std::size_t kN = RayBlock::kSize;

// Lane-wise select; compiles to a blend.
inline double Select(bool condition, double a, double b) { return condition ? a : b; }

// Statuses carried as doubles inside the vector loop (one lane type keeps it vectorisable).
constexpr double kHit = static_cast<double>(HitStatus::kHit);
constexpr double kParallel = static_cast<double>(HitStatus::kParallel);
constexpr double kBehind = static_cast<double>(HitStatus::kBehind);
constexpr double kOutsideSurface = static_cast<double>(HitStatus::kOutsideSurface);
constexpr double kNoIntersection = static_cast<double>(HitStatus::kNoIntersection);

// The cone's frame as plain numbers, for the vector lanes: s = S x + c.
struct ConeFrame {
  double s00, s01, s02, s10, s11, s12, s20, s21, s22;
  double c0, c1, c2;
};

ConeFrame FrameOf(const PreparedCone& cone) {
  const Eigen::Matrix3d& S = cone.S_C;
  return {S(0, 0), S(0, 1), S(0, 2), S(1, 0),           S(1, 1),           S(1, 2),
          S(2, 0), S(2, 1), S(2, 2), cone.s_origin.x(), cone.s_origin.y(), cone.s_origin.z()};
}

// Whether a crossing at (u, y, z) in cone coordinates, of a ray of direction (du, dy, dz) there
// and d_C in {C}, meets the cone within the minimum angle: its squared sine to the cone's tangent
// plane at most min_sin2. In cone coordinates the cone is F(s) = y^2 - b^2 (z^2 - u^2) = 0, its
// normal grad F / 2 = (b^2 u, y, -b^2 z) (for b = 0 the plane y = 0: (0, 1, 0)); in {C} the normal
// is S^T times that, and grad F . (S d_C) is its product with d_C.
inline bool Grazing(const ConeFrame& f, double bb, double u, double y, double z, double du,
                    double dy, double dz, double d2_C, double min_sin2) {
  const bool planar = bb == 0.0;
  const double gu = Select(planar, 0.0, bb * u);
  const double gy = Select(planar, 1.0, y);
  const double gz = Select(planar, 0.0, -bb * z);
  const double along = gu * du + gy * dy + gz * dz;
  const double nx = f.s00 * gu + f.s10 * gy + f.s20 * gz;
  const double ny = f.s01 * gu + f.s11 * gy + f.s21 * gz;
  const double nz = f.s02 * gu + f.s12 * gy + f.s22 * gz;
  return along * along <= min_sin2 * (nx * nx + ny * ny + nz * nz) * d2_C;
}

// The loop runs over the lanes of the block; every lane follows exactly the arithmetic of the
// per-ray IntersectRayCone, with its early returns turned into masks, then the grazing test.
// The clones belong to this internal function, not to the one the header declares: clang 14
// compiles a target_clones definition that has an earlier plain declaration into its first
// clone alone, without dispatch (an AVX-512 function that stops other CPUs with SIGILL).
__attribute__((target_clones("avx512f", "avx2", "default"))) void IntersectLanes(
    const PreparedCone& cone, const RayBlock& rays, double min_sin2_angle, HitBlock* hits) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const ConeFrame f = FrameOf(cone);
  const double bb = cone.b * cone.b, abs_b = std::abs(cone.b);
  const double b = cone.b, h_min = cone.h_min_m, cos_min = cone.cos_beta_min,
               cos_max = cone.cos_beta_max, coefficient_tol = cone.coefficient_tol,
               origin_size = cone.origin_size;

#pragma omp simd
  for (std::size_t i = 0; i < kN; ++i) {
    // Ray in cone coordinates s = S x + s_origin.
    const double ox = f.s00 * rays.ox[i] + f.s01 * rays.oy[i] + f.s02 * rays.oz[i] + f.c0;
    const double oy = f.s10 * rays.ox[i] + f.s11 * rays.oy[i] + f.s12 * rays.oz[i] + f.c1;
    const double oz = f.s20 * rays.ox[i] + f.s21 * rays.oy[i] + f.s22 * rays.oz[i] + f.c2;
    const double dx = f.s00 * rays.dx[i] + f.s01 * rays.dy[i] + f.s02 * rays.dz[i];
    const double dy = f.s10 * rays.dx[i] + f.s11 * rays.dy[i] + f.s12 * rays.dz[i];
    const double dz = f.s20 * rays.dx[i] + f.s21 * rays.dy[i] + f.s22 * rays.dz[i];

    const double g2 = (dz - dx) * (dz + dx);
    const double g1 = oz * dz - ox * dx;
    const double g0 = (oz - ox) * (oz + ox);
    const double qa_raw = dy * dy - bb * g2;
    const double qb = oy * dy - bb * g1;
    const double qc = oy * oy - bb * g0;

    const double o_size = std::abs(ox) + std::abs(oy) + std::abs(oz) + origin_size;
    const double d_size = std::abs(dx) + std::abs(dy) + std::abs(dz);
    const double tol = coefficient_tol * d_size;
    const bool qa_zero = std::abs(qa_raw) <= tol * d_size;
    const bool parallel = qa_zero & (std::abs(qb) <= tol * o_size);
    const double qa = Select(qa_zero, 0.0, qa_raw);

    const double mx = oy * dz - oz * dy;
    const double my = oz * dx - ox * dz;
    const double mz = ox * dy - oy * dx;
    const double disc_over_bb = (mx - mz) * (mx + mz) + bb * my * my;
    const bool no_intersection = !(disc_over_bb >= 0.0) & (bb != 0.0);
    const double sqrt_disc = abs_b * std::sqrt(disc_over_bb > 0.0 ? disc_over_bb : 0.0);
    const double q = -(qb + std::copysign(sqrt_disc, qb));
    const double t1 = q / qa;
    const double t2 = qc / q;

    const double apex_tol = detail::kConeApexTol * o_size * d_size;
    const bool through_apex = mx * mx + my * my + mz * mz <= apex_tol * apex_tol;
    const double t_near = t2 < t1 ? t2 : t1;
    const double t_far = t2 > t1 ? t2 : t1;
    const double un = ox + t_near * dx, yn = oy + t_near * dy, zn = oz + t_near * dz;
    const bool lit_near = (t_near >= 0.0) & (t_near < kInf) & (zn > h_min) & (yn * b >= 0.0) &
                          (un >= cos_max * zn) & (un <= cos_min * zn);
    const double uf = ox + t_far * dx, yf = oy + t_far * dy, zf = oz + t_far * dz;
    const bool lit_far = (t_far >= 0.0) & (t_far < kInf) & (zf > h_min) & (yf * b >= 0.0) &
                         (uf >= cos_max * zf) & (uf <= cos_min * zf);
    const bool ahead = ((t1 >= 0.0) & (t1 < kInf)) | ((t2 >= 0.0) & (t2 < kInf));

    const bool candidate = !(parallel | no_intersection | through_apex);
    const bool hit_near = candidate & lit_near;
    const bool hit_far = candidate & !lit_near & lit_far;
    const double d2_C = rays.dx[i] * rays.dx[i] + rays.dy[i] * rays.dy[i] + rays.dz[i] * rays.dz[i];
    const bool grazing = Grazing(f, bb, Select(hit_near, un, uf), Select(hit_near, yn, yf),
                                 Select(hit_near, zn, zf), dx, dy, dz, d2_C, min_sin2_angle);
    const bool hit = (hit_near | hit_far) & !grazing;
    const double t = Select(hit_near, t_near, Select(hit_far, t_far, 0.0));
    // Status in the per-ray function's order of tests, as a lane-wise select chain.
    double status = Select(ahead, kOutsideSurface, kBehind);
    status = Select(hit_near | hit_far, Select(grazing, kParallel, kHit), status);
    status = Select(no_intersection, kNoIntersection, status);
    status = Select(parallel, kParallel, status);
    hits->status[i] = status;
    hits->t[i] = Select(hit, t, 0.0);
    hits->x[i] = Select(hit, rays.ox[i] + t * rays.dx[i], 0.0);
    hits->y[i] = Select(hit, rays.oy[i] + t * rays.dy[i], 0.0);
    hits->z[i] = Select(hit, rays.oz[i] + t * rays.dz[i], 0.0);
  }
}

}  // namespace

void IntersectRayConeBlock(const PreparedCone& cone, const RayBlock& rays, double min_sin2_angle,
                           HitBlock* hits) {
  IntersectLanes(cone, rays, min_sin2_angle, hits);
}

}  // namespace uwscan::scanner
