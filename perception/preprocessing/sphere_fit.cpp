#include "perception/preprocessing/sphere_fit.hpp"

#include <Eigen/Dense>
#include <cmath>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

constexpr int kMaxGaussNewtonSteps = 50;

void Residuals(std::span<const Eigen::Vector3d> points, SphereFit* fit) {
  double sum2 = 0.0;
  fit->max_abs_m = 0.0;
  for (const Eigen::Vector3d& p : points) {
    const double r = (p - fit->centre).norm() - fit->radius_m;
    sum2 += r * r;
    fit->max_abs_m = std::max(fit->max_abs_m, std::abs(r));
  }
  fit->rms_m = std::sqrt(sum2 / static_cast<double>(points.size()));
}

}  // namespace

SphereFit FitSphere(std::span<const Eigen::Vector3d> points) {
  if (points.size() < 4) throw Error("sphere fit: needs at least 4 points");
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) throw Error("sphere fit: a point is not finite");
    mean += p;
  }
  mean /= static_cast<double>(points.size());
  double scale = 0.0;
  for (const Eigen::Vector3d& p : points) scale = std::max(scale, (p - mean).norm());
  if (!(scale > 0.0)) throw Error("sphere fit: all points coincide");

  // |q|^2 = 2 c.q + k with q the centred, scaled points and k = r^2 - |c|^2.
  const Eigen::Index n = static_cast<Eigen::Index>(points.size());
  Eigen::MatrixXd a(n, 4);
  Eigen::VectorXd b(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d q = (points[static_cast<size_t>(i)] - mean) / scale;
    a.row(i) << 2.0 * q.x(), 2.0 * q.y(), 2.0 * q.z(), 1.0;
    b(i) = q.squaredNorm();
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  qr.setThreshold(1e-10);
  if (qr.rank() < 4) throw Error("sphere fit: the points are coplanar or collinear");
  const Eigen::Vector4d x = qr.solve(b);
  const double r2 = x(3) + x.head<3>().squaredNorm();
  if (!(r2 > 0.0)) throw Error("sphere fit: the points do not determine a sphere");

  SphereFit fit;
  Eigen::Vector3d c = x.head<3>();
  double r = std::sqrt(r2);
  // Gauss-Newton on d_i = |q_i - c| - r, in the scaled frame.
  for (int step = 0; step < kMaxGaussNewtonSteps; ++step) {
    Eigen::MatrixXd j(n, 4);
    Eigen::VectorXd d(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Vector3d q = (points[static_cast<size_t>(i)] - mean) / scale;
      const Eigen::Vector3d diff = q - c;
      const double dist = diff.norm();
      const Eigen::Vector3d unit =
          dist > 0.0 ? Eigen::Vector3d(diff / dist) : Eigen::Vector3d::Zero();
      j.row(i) << -unit.x(), -unit.y(), -unit.z(), -1.0;
      d(i) = dist - r;
    }
    const Eigen::Vector4d delta = j.colPivHouseholderQr().solve(-d);
    c += delta.head<3>();
    r += delta(3);
    fit.iterations = step + 1;
    if (delta.norm() <= 1e-14 * (1.0 + r)) break;
  }
  fit.centre = mean + scale * c;
  fit.radius_m = scale * std::abs(r);
  Residuals(points, &fit);
  return fit;
}

}  // namespace uwscan::perception
