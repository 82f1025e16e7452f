#include "mapping/slam/overlap_gate.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

#include "scanner/common/symmetrized.hpp"

namespace uwscan::mapping {
namespace {

constexpr double kNoVariance_m2 = 1e-300;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// In C's eigenbasis (variances s, gap g): the part of the gap left for lambda, |g_i / (1 + lambda
// s_i)|.
double Left(const Eigen::Vector3d& g, const Eigen::Vector3d& s, double lambda) {
  return g.cwiseQuotient((Eigen::Vector3d::Ones() + lambda * s)).norm();
}

// The Mahalanobis norm of the error d_i = -g_i lambda s_i / (1 + lambda s_i): sum d_i^2 / s_i.
double ErrorNorm(const Eigen::Vector3d& g, const Eigen::Vector3d& s, double lambda) {
  double m2 = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (s[i] <= kNoVariance_m2) continue;
    const double d = std::isinf(lambda) ? g[i] : g[i] * lambda * s[i] / (1.0 + lambda * s[i]);
    m2 += d * d / s[i];
  }
  return std::sqrt(m2);
}

}  // namespace

double MahalanobisGapToOverlap(const Eigen::Vector3d& gap_m, double overlap_m,
                               const Eigen::Matrix3d& covariance) {
  if (!gap_m.allFinite() || !covariance.allFinite() || !std::isfinite(overlap_m)) return kInfinity;
  if (gap_m.norm() <= overlap_m) return 0.0;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(Symmetrized(covariance));
  const Eigen::Vector3d s = eigen.eigenvalues().cwiseMax(0.0);
  const Eigen::Vector3d g = eigen.eigenvectors().transpose() * gap_m;
  // What no amount of error can close: the gap along directions without variance.
  double stuck2 = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (s[i] <= kNoVariance_m2) stuck2 += g[i] * g[i];
  }
  if (std::sqrt(stuck2) >= overlap_m) return kInfinity;
  // Bracket lambda by doubling, then bisect to the last bit of the bracket. Left falls to the
  // stuck part, below the overlap, as lambda grows; if doubling ever reached the largest double
  // (variances near 1e-300), lambda -> infinity is the answer: the whole gap closed.
  double low = 0.0, high = 1.0 / s.maxCoeff();
  while (Left(g, s, high) > overlap_m) {
    if (high > 0.25 * std::numeric_limits<double>::max()) return ErrorNorm(g, s, kInfinity);
    high *= 2.0;
  }
  for (int k = 0; k < 200 && high - low > 1e-15 * high; ++k) {
    const double mid = 0.5 * (low + high);
    (Left(g, s, mid) > overlap_m ? low : high) = mid;
  }
  return ErrorNorm(g, s, high);
}

}  // namespace uwscan::mapping
