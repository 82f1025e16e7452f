#include "scanner/triangulation/light_plane.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <sstream>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::scanner {
namespace {

// Second singular value over the largest below which the points are taken as collinear. The
// SVD of the centred points resolves singular values to ~1e-16 of the largest, so 1e-9 is far
// above rounding and far below any laser fan worth fitting (1 nm over 1 m).
constexpr double kCollinearRatio = 1e-9;

void CheckPlaneInput(std::span<const Eigen::Vector3d> points) {
  if (points.size() < 3) {
    throw Error("FitPlane: need at least 3 points, got " + std::to_string(points.size()));
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      std::ostringstream message;
      message << "FitPlane: point " << i << " is not finite (" << points[i].transpose() << ")";
      throw Error(message.str());
    }
  }
}

}  // namespace

PlaneFit FitPlane(std::span<const Eigen::Vector3d> points) {
  CheckPlaneInput(points);
  const Eigen::Index n = static_cast<Eigen::Index>(points.size());

  // Centre first: the singular vectors of the raw coordinates would mix the plane offset into
  // the normal and lose digits for planes far from the origin.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) {
    centroid += p;
  }
  centroid /= static_cast<double>(n);
  Eigen::MatrixX3d centred(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    centred.row(i) = (points[i] - centroid).transpose();
  }

  // SVD of the data rather than an eigen-decomposition of its covariance: squaring the data
  // would halve the digits of a nearly degenerate (thin) point set.
  const Eigen::JacobiSVD<Eigen::MatrixX3d> svd(centred, Eigen::ComputeFullV);
  const Eigen::Vector3d& sigma = svd.singularValues();  // descending
  if (!(sigma(1) > kCollinearRatio * sigma(0))) {
    std::ostringstream message;
    message << "FitPlane: the " << n << " points do not span a plane (singular values "
            << sigma.transpose() << "); they are coincident or collinear";
    throw Error(message.str());
  }

  PlaneFit fit;
  fit.plane.normal = svd.matrixV().col(2).normalized();
  fit.plane.offset_m = fit.plane.normal.dot(centroid);
  if (fit.plane.offset_m < 0.0) {
    fit.plane.normal = -fit.plane.normal;
    fit.plane.offset_m = -fit.plane.offset_m;
  }
  double sum_sq = 0.0;
  for (const Eigen::Vector3d& p : points) {
    const double d = fit.plane.normal.dot(p - centroid);  // centred: no digits lost to offset
    sum_sq += d * d;
    fit.max_abs_m = std::max(fit.max_abs_m, std::abs(d));
  }
  fit.rms_m = std::sqrt(sum_sq / static_cast<double>(n));
  return fit;
}

}  // namespace uwscan::scanner
