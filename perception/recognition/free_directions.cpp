#include "perception/recognition/free_directions.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

#include "scanner/common/error.hpp"
#include "scanner/common/symmetrized.hpp"

namespace uwscan::perception {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

// A combination of free directions whose rotation, in metres at the object's radius, is under
// this share of its motion is a slide (locally, a rotation about an axis that far away is one).
constexpr double kTranslationShare = 0.1;

void Check(const Matrix6d& information, const Matrix6d& patch_spread,
           const Eigen::Vector3d& centre_O, double sigma_m, double radius_m, double tolerance_m) {
  if (!information.allFinite() || !information.isApprox(information.transpose(), 1e-9)) {
    throw Error("free directions: the information must be a finite, symmetric 6x6 matrix");
  }
  if (!patch_spread.allFinite() || !patch_spread.isApprox(patch_spread.transpose(), 1e-9)) {
    throw Error("free directions: the patch spread must be a finite, symmetric 6x6 matrix");
  }
  if (!centre_O.allFinite()) throw Error("free directions: the centre must be finite");
  if (!(sigma_m > 0.0 && std::isfinite(sigma_m)))
    throw Error("free directions: sigma_m must be positive");
  if (!(radius_m > 0.0 && std::isfinite(radius_m)))
    throw Error("free directions: radius_m must be positive");
  if (!(tolerance_m > 0.0 && std::isfinite(tolerance_m))) {
    throw Error("free directions: tolerance_m must be positive");
  }
}

FreeDirection Free(FreeMotion motion, const Eigen::Vector3d& axis_O,
                   const Eigen::Vector3d& point_O) {
  FreeDirection f;
  f.kind = FreeKind::kUnconstrained;
  f.motion = motion;
  f.axis_S = axis_O;
  f.point_S = point_O;
  return f;
}

// A twist [w, v] (x -> x + w x (x - c) + v) as a rotation about its axis: the axis through
// c + w x v / |w|^2 along w (its pitch, v along w, is dropped).
FreeDirection Rotation(const Vector6d& twist, const Eigen::Vector3d& centre_O) {
  const Eigen::Vector3d w = twist.head<3>(), v = twist.tail<3>();
  return Free(FreeMotion::kRotation, w.normalized(), centre_O + w.cross(v) / w.squaredNorm());
}

// Two free twists combined into the two whose pitch w . v is zero, when there are two: the
// pitch of x1 t1 + x2 t2 is the quadratic form x^T Q x, Q_ij = (w_i . v_j + w_j . v_i) / 2, with
// two real null directions when Q is indefinite. When Q vanishes every combination is a pure
// rotation (the axes meet) and the twists are kept; when it is definite none is, and they are
// kept as the screws they are.
std::pair<Vector6d, Vector6d> PureRotations(const Vector6d& a, const Vector6d& b) {
  const auto pitch = [](const Vector6d& s, const Vector6d& t) {
    return 0.5 * (s.head<3>().dot(t.tail<3>()) + t.head<3>().dot(s.tail<3>()));
  };
  Eigen::Matrix2d Q;
  Q << pitch(a, a), pitch(a, b), pitch(a, b), pitch(b, b);
  const double scale =
      std::max(a.head<3>().norm() * a.tail<3>().norm(), b.head<3>().norm() * b.tail<3>().norm());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(Q);
  const double low = eigen.eigenvalues()[0], high = eigen.eigenvalues()[1];
  if (std::max(std::abs(low), std::abs(high)) <= 1e-9 * scale || !(low < 0.0 && high > 0.0))
    return {a, b};
  // x = cos(t) e_low + sin(t) e_high with low cos^2 + high sin^2 = 0.
  const double t = std::atan(std::sqrt(-low / high));
  const Eigen::Vector2d e_low = eigen.eigenvectors().col(0), e_high = eigen.eigenvectors().col(1);
  const Eigen::Vector2d x1 = std::cos(t) * e_low + std::sin(t) * e_high;
  const Eigen::Vector2d x2 = std::cos(t) * e_low - std::sin(t) * e_high;
  return {x1[0] * a + x1[1] * b, x2[0] * a + x2[1] * b};
}

void AppendColumn(Eigen::Matrix<double, 6, Eigen::Dynamic>& columns, const Vector6d& u) {
  columns.conservativeResize(Eigen::NoChange, columns.cols() + 1);
  columns.col(columns.cols() - 1) = u;
}

// Moves the directions whose variance in `covariance` (scaled, over the pinned directions, the
// restarts' `rest` included) exceeds tolerance_m^2 to `free`, and takes them out of the
// covariance: its own eigenvectors, not the information's, so that one flat direction (a slide
// the restarts show) is freed as itself rather than leaking into every direction it has a share
// of. Only where the restarts alone spread over half the tolerance: what is freed here is what
// they show, never what the information's cross terms add up to (with restarts that all come
// back, the free directions are the information's).
void FreeWhatTheFitDoesNotHold(double tolerance_m, const Matrix6d& rest, Matrix6d& covariance,
                               Eigen::Matrix<double, 6, Eigen::Dynamic>& free) {
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(Symmetrized(covariance));
  const double tolerance2 = tolerance_m * tolerance_m;
  Matrix6d held = Matrix6d::Identity();  // projector onto what stays pinned
  for (int k = 0; k < 6; ++k) {
    const Vector6d u = eigen.eigenvectors().col(k);
    if (eigen.eigenvalues()[k] <= tolerance2 || u.dot(rest * u) <= 0.25 * tolerance2) continue;
    AppendColumn(free, u);
    held -= u * u.transpose();
  }
  covariance = held * covariance * held;
}

}  // namespace

PoseConstraints AnalysePoseConstraints(const Matrix6d& information, const Matrix6d& patch_spread,
                                       const Eigen::Vector3d& centre_O, double sigma_m,
                                       double radius_m, double tolerance_m, double floor_std_m,
                                       const Matrix6d& rest_spread) {
  Check(information, patch_spread, centre_O, sigma_m, radius_m, tolerance_m);
  if (!(floor_std_m >= 0.0 && std::isfinite(floor_std_m)))
    throw Error("free directions: floor_std_m must be >= 0");
  if (!rest_spread.allFinite() || !rest_spread.isApprox(rest_spread.transpose(), 1e-9))
    throw Error("free directions: the rest spread must be a finite, symmetric 6x6 matrix");
  // Rotations scaled by the radius: both halves in metres, so one tolerance judges both.
  Matrix6d D = Matrix6d::Identity();
  D.topLeftCorner<3, 3>() *= 1.0 / radius_m;
  const Matrix6d scaled = D * Symmetrized(information) * D;
  const Matrix6d spread = D * Symmetrized(patch_spread) * D;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(scaled);
  PoseConstraints out;
  Matrix6d inverse = Matrix6d::Zero();  // over the pinned directions, scaled
  Matrix6d pinned = Matrix6d::Zero();   // projector onto them
  Eigen::Matrix<double, 6, Eigen::Dynamic> free(6, 0);
  for (int k = 0; k < 6; ++k) {
    const Vector6d u = eigen.eigenvectors().col(k);
    const double lambda = eigen.eigenvalues()[k];
    // Variance along u: sigma^2 / lambda + u^T S u / lambda^2 (infinite with no information).
    const double variance = lambda > 0.0 ? (sigma_m * sigma_m + u.dot(spread * u) / lambda) / lambda
                                         : std::numeric_limits<double>::infinity();
    if (variance <= tolerance_m * tolerance_m) {
      inverse += u * u.transpose() / lambda;
      pinned += u * u.transpose();
    } else {
      AppendColumn(free, u);
    }
  }
  Matrix6d covariance = sigma_m * sigma_m * inverse + inverse * spread * inverse +
                        floor_std_m * floor_std_m * pinned;  // scaled
  const Matrix6d rest = pinned * D.inverse() * Symmetrized(rest_spread) * D.inverse() * pinned;
  covariance += rest;
  FreeWhatTheFitDoesNotHold(tolerance_m, rest, covariance, free);
  out.covariance = D * covariance * D;
  if (free.cols() == 0) return out;

  // Combinations of the free directions by how much they turn: the right singular vectors of
  // their rotation halves, most turning first.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(free.topRows<3>(), Eigen::ComputeFullV);
  const Eigen::VectorXd& turning = svd.singularValues();
  std::vector<Vector6d> rotations;  // unscaled twists
  std::vector<Eigen::Vector3d> slides;
  for (Eigen::Index j = 0; j < free.cols(); ++j) {
    const Vector6d scaled_twist = free * svd.matrixV().col(j);
    const double turn = j < turning.size() ? turning[j] : 0.0;
    if (turn >= kTranslationShare) {
      rotations.push_back(D * scaled_twist);
      continue;
    }
    Eigen::Vector3d axis = scaled_twist.tail<3>();
    for (const Eigen::Vector3d& s : slides) axis -= axis.dot(s) * s;  // orthonormal slides
    if (axis.norm() > 1e-6) slides.push_back(axis.normalized());
  }
  for (const Eigen::Vector3d& s : slides)
    out.free_O.push_back(Free(FreeMotion::kTranslation, s, centre_O));
  // A free slide can be added to any rotation: taken out, the rotation's axis is the one that
  // moves least, e.g. a pipe's roll about its own axis rather than a screw along it.
  for (Vector6d& r : rotations) {
    for (const Eigen::Vector3d& s : slides) r.tail<3>() -= r.tail<3>().dot(s) * s;
  }
  if (rotations.size() == 2) {
    const auto [a, b] = PureRotations(rotations[0], rotations[1]);
    rotations = {a, b};
  }
  for (const Vector6d& r : rotations) out.free_O.push_back(Rotation(r, centre_O));
  return out;
}

std::string ToString(FreeKind kind) {
  return kind == FreeKind::kSymmetry ? "symmetry" : "unconstrained";
}

std::string ToString(FreeMotion motion) {
  return motion == FreeMotion::kRotation ? "rotation" : "translation";
}

}  // namespace uwscan::perception
