#include "perception/registration/svd_alignment.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <cstddef>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

// Relative tolerance on the second singular value (largest = 1) below which the points are
// taken to span less than a plane.
constexpr double kRankTolerance = 1e-12;

bool HasRankAtLeastTwo(const Eigen::Vector3d& singular_values_descending) {
  return singular_values_descending(0) > 0.0 &&
         singular_values_descending(1) > kRankTolerance * singular_values_descending(0);
}

// Eigenvalues (= singular values) of a symmetric positive semi-definite matrix, largest first.
Eigen::Vector3d EigenvaluesDescending(const Eigen::Matrix3d& covariance) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d ascending = solver.eigenvalues().cwiseMax(0.0);
  return Eigen::Vector3d(ascending(2), ascending(1), ascending(0));
}

}  // namespace

SvdAlignment AlignSvd(std::span<const Eigen::Vector3d> source_points,
                      std::span<const Eigen::Vector3d> target_points,
                      std::span<const double> weights) {
  const std::size_t n = source_points.size();
  if (target_points.size() != n) {
    throw Error("AlignSvd: target_points has " + std::to_string(target_points.size()) +
                " points, source_points has " + std::to_string(n));
  }
  if (!weights.empty() && weights.size() != n) {
    throw Error("AlignSvd: weights has " + std::to_string(weights.size()) +
                " entries, expected 0 or " + std::to_string(n));
  }
  const auto weight = [&](std::size_t i) { return weights.empty() ? 1.0 : weights[i]; };
  std::size_t positive = 0;
  double weight_sum = 0.0;
  Eigen::Vector3d source_sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d target_sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    if (!source_points[i].allFinite() || !target_points[i].allFinite()) {
      throw Error("AlignSvd: pair " + std::to_string(i) + " has a non-finite point");
    }
    const double w = weight(i);
    if (!std::isfinite(w) || w < 0.0) {
      throw Error("AlignSvd: weights[" + std::to_string(i) + "] = " + std::to_string(w) +
                  ", expected a finite value >= 0");
    }
    if (w == 0.0) continue;
    ++positive;
    weight_sum += w;
    source_sum += w * source_points[i];
    target_sum += w * target_points[i];
  }
  SvdAlignment result;
  if (positive < 3) return result;
  const Eigen::Vector3d source_centroid = source_sum / weight_sum;
  const Eigen::Vector3d target_centroid = target_sum / weight_sum;

  Eigen::Matrix3d cross = Eigen::Matrix3d::Zero();  // H = sum w (s - s0)(t - t0)^T
  Eigen::Matrix3d source_cov = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d target_cov = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const double w = weight(i);
    if (w == 0.0) continue;
    const Eigen::Vector3d s = source_points[i] - source_centroid;
    const Eigen::Vector3d t = target_points[i] - target_centroid;
    cross += w * s * t.transpose();
    source_cov += w * s * s.transpose();
    target_cov += w * t * t.transpose();
  }
  if (!HasRankAtLeastTwo(EigenvaluesDescending(source_cov)) ||
      !HasRankAtLeastTwo(EigenvaluesDescending(target_cov))) {
    return result;
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(cross, Eigen::ComputeFullU | Eigen::ComputeFullV);
  if (!HasRankAtLeastTwo(svd.singularValues())) return result;

  const Eigen::Matrix3d& U = svd.matrixU();
  const Eigen::Matrix3d& V = svd.matrixV();
  Eigen::Vector3d d(1.0, 1.0, (V * U.transpose()).determinant() < 0.0 ? -1.0 : 1.0);
  const Eigen::Matrix3d R = V * d.asDiagonal() * U.transpose();

  result.T_target_source.linear() = R;
  result.T_target_source.translation() = target_centroid - R * source_centroid;
  result.status = SvdAlignmentStatus::kSuccess;
  double squared_sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double w = weight(i);
    if (w == 0.0) continue;
    squared_sum +=
        w * (R * (source_points[i] - source_centroid) - (target_points[i] - target_centroid))
                .squaredNorm();
  }
  result.rmse_m = std::sqrt(squared_sum / weight_sum);
  return result;
}

}  // namespace uwscan::perception
