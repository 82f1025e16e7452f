#include "mapping/slam/overlap_gate.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

namespace uwscan::mapping {
namespace {

constexpr double kNoVariance_m2 = 1e-300;

// In C's eigenbasis (variances s, gap g): the part of the gap left for lambda, |g_i / (1 + lambda s_i)|.
double Left(const Eigen::Vector3d& g, const Eigen::Vector3d& s, double lambda) {
  return g.cwiseQuotient((Eigen::Vector3d::Ones() + lambda * s)).norm();
}

}  // namespace

double MahalanobisGapToOverlap(const Eigen::Vector3d& gap, double overlap_m, const Eigen::Matrix3d& covariance) {
  if (gap.norm() <= overlap_m) return 0.0;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(0.5 * (covariance + covariance.transpose()));
  const Eigen::Vector3d s = eigen.eigenvalues().cwiseMax(0.0);
  const Eigen::Vector3d g = eigen.eigenvectors().transpose() * gap;
  // What no amount of error can close: the gap along directions without variance.
  double stuck2 = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (s[i] <= kNoVariance_m2) stuck2 += g[i] * g[i];
  }
  if (std::sqrt(stuck2) > overlap_m) return std::numeric_limits<double>::infinity();
  // Bracket lambda, then bisect to the last bit of the bracket.
  double low = 0.0, high = 1.0 / s.maxCoeff();
  for (int doublings = 0; Left(g, s, high) > overlap_m; ++doublings) {
    if (doublings == 2000) return std::numeric_limits<double>::infinity();  // only at the limit
    high *= 2.0;
  }
  for (int k = 0; k < 200 && high - low > 1e-15 * high; ++k) {
    const double mid = 0.5 * (low + high);
    (Left(g, s, mid) > overlap_m ? low : high) = mid;
  }
  // d_i = -g_i lambda s_i / (1 + lambda s_i); its squared norm under C is sum d_i^2 / s_i.
  double m2 = 0.0;
  for (int i = 0; i < 3; ++i) {
    if (s[i] <= kNoVariance_m2) continue;
    const double d = g[i] * high * s[i] / (1.0 + high * s[i]);
    m2 += d * d / s[i];
  }
  return std::sqrt(m2);
}

}  // namespace uwscan::mapping
