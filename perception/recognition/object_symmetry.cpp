#include "perception/recognition/object_symmetry.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "perception/cloud/cloud_neighbors.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::perception {
namespace {

Eigen::Isometry3d RotationAbout(const SymmetryAxis& axis, double angle_rad) {
  return Eigen::Translation3d(axis.point_O) * Eigen::AngleAxisd(angle_rad, axis.axis_O) *
         Eigen::Translation3d(-axis.point_O);
}

double SurfaceArea(const scanner::TriangleMesh& mesh) {
  double area = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[static_cast<std::size_t>(t[0])];
    area += 0.5 * (mesh.vertices[static_cast<std::size_t>(t[1])] - a)
                      .cross(mesh.vertices[static_cast<std::size_t>(t[2])] - a)
                      .norm();
  }
  return area;
}

// Farthest any moved test point lies from the surface samples, metres.
double WorstDistance(const KnnIndex& index, const std::vector<Eigen::Vector3f>& test_points,
                     const Eigen::Isometry3d& T) {
  std::vector<std::uint32_t> nearest;
  std::vector<float> squared;
  double worst = 0.0;
  const Eigen::Isometry3f Tf = T.cast<float>();
  for (const Eigen::Vector3f& p : test_points) {
    index.Query(Tf * p, 1, nearest, squared);
    worst = std::max(worst, static_cast<double>(squared[0]));
  }
  return std::sqrt(worst);
}

}  // namespace

std::vector<Eigen::Isometry3d> SymmetryTransforms(std::span<const SymmetryAxis> axes,
                                                  double continuous_step_rad) {
  if (!(continuous_step_rad > 0.0)) throw Error("symmetries: the sampling step must be > 0");
  std::vector<Eigen::Isometry3d> transforms = {Eigen::Isometry3d::Identity()};
  for (const SymmetryAxis& axis : axes) {
    if (axis.order == 1 || axis.order < 0) throw Error("symmetries: an order must be 0 or >= 2");
    const int steps =
        axis.continuous()
            ? std::max(2, static_cast<int>(std::ceil(2.0 * std::numbers::pi / continuous_step_rad)))
            : axis.order;
    std::vector<Eigen::Isometry3d> product;
    for (const Eigen::Isometry3d& T : transforms) {
      for (int k = 0; k < steps; ++k) {
        product.push_back(RotationAbout(axis, 2.0 * std::numbers::pi * k / steps) * T);
      }
    }
    transforms = std::move(product);
  }
  return transforms;
}

void SymmetryDetectionOptions::Check() const {
  const OptionChecks check("SymmetryDetectionOptions");
  check.AtLeast("samples", samples, 1000);
  check.AtLeast("test_points", test_points, 100);
  check.AtLeast("max_order", max_order, 2);
  check.AtLeast("tolerance_fraction", tolerance_fraction, 0.0);
}

std::vector<SymmetryAxis> DetectSymmetries(const scanner::TriangleMesh& mesh,
                                           const SymmetryDetectionOptions& options) {
  options.Check();
  if (mesh.triangles.empty()) throw Error("symmetry detection: the mesh has no triangles");
  const scanner::SurfaceSamples surface =
      scanner::SampleSurface(mesh, options.samples, options.seed);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : surface.points) centroid += p;
  centroid /= static_cast<double>(surface.points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  std::vector<Eigen::Vector3f> relative;
  for (const Eigen::Vector3d& p : surface.points) {
    scatter += (p - centroid) * (p - centroid).transpose();
    relative.push_back((p - centroid).cast<float>());
  }
  const KnnIndex index(relative);
  std::vector<Eigen::Vector3f> test_points;
  const std::size_t stride = std::max<std::size_t>(1, relative.size() / options.test_points);
  for (std::size_t i = 0; i < relative.size(); i += stride) test_points.push_back(relative[i]);

  const double spacing = std::sqrt(SurfaceArea(mesh) / options.samples);
  const double tolerance = 2.0 * spacing + options.tolerance_fraction * mesh.BoundingBoxDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> principal(scatter);
  std::vector<SymmetryAxis> found;
  for (int a = 2; a >= 0; --a) {
    SymmetryAxis axis;
    axis.axis_O = principal.eigenvectors().col(a).normalized();
    const SymmetryAxis about_origin{Eigen::Vector3d::Zero(), axis.axis_O, 0};
    auto passes = [&](double angle) {
      return WorstDistance(index, test_points, RotationAbout(about_origin, angle)) < tolerance;
    };
    if (passes(0.37) && passes(1.3) && passes(2.9)) {
      axis.order = 0;
    } else {
      for (int n = options.max_order; n >= 2 && axis.order == 0; --n) {
        if (passes(2.0 * std::numbers::pi / n)) axis.order = n;
      }
      if (axis.order == 0) continue;
    }
    axis.point_O = centroid;
    // Redundant axes (a pipe's two perpendicular 2-fold flips) are kept: SymmetryTransforms
    // then lists some poses twice, which costs time, not correctness.
    found.push_back(axis);
  }
  return found;
}

SymmetricPoseError PoseErrorModuloSymmetry(const Eigen::Isometry3d& T_est,
                                           const Eigen::Isometry3d& T_true,
                                           std::span<const Eigen::Vector3d> model_points_O,
                                           std::span<const Eigen::Isometry3d> symmetries) {
  if (model_points_O.empty() || symmetries.empty()) {
    throw Error("pose error: needs model points and at least the identity symmetry");
  }
  SymmetricPoseError best;
  best.mssd_m = std::numeric_limits<double>::infinity();
  for (std::size_t s = 0; s < symmetries.size(); ++s) {
    const Eigen::Isometry3d T = T_true * symmetries[s];
    double worst = 0.0;
    for (const Eigen::Vector3d& x : model_points_O) {
      worst = std::max(worst, (T_est * x - T * x).squaredNorm());
      if (worst >= best.mssd_m * best.mssd_m) break;
    }
    const double mssd = std::sqrt(worst);
    if (mssd < best.mssd_m) {
      best.mssd_m = mssd;
      best.rotation_rad = Eigen::AngleAxisd((T.linear().transpose() * T_est.linear())).angle();
      best.translation_m = (T_est.translation() - T.translation()).norm();
      best.T_symmetric = T;
    }
  }
  return best;
}

SymmetricPoseError PoseErrorModuloSymmetry(const Eigen::Isometry3d& T_est,
                                           const Eigen::Isometry3d& T_true,
                                           std::span<const Eigen::Vector3d> model_points_O,
                                           std::span<const SymmetryAxis> axes) {
  const std::vector<Eigen::Isometry3d> symmetries = SymmetryTransforms(axes);
  SymmetricPoseError e = PoseErrorModuloSymmetry(T_est, T_true, model_points_O, symmetries);
  for (const SymmetryAxis& axis : axes) {
    if (!axis.continuous()) continue;
    // With q = (w, v) the relative rotation, turning the truth by t about the axis a leaves
    // cos(t / 2) w + sin(t / 2) (a . v) as the real part, largest at t = 2 atan2(a . v, w).
    const Eigen::Vector3d a = axis.axis_O.normalized();
    const Eigen::Quaterniond q(e.T_symmetric.linear().transpose() * T_est.linear());
    const double turn = 2.0 * std::atan2(a.dot(q.vec()), q.w());
    e.T_symmetric = e.T_symmetric * RotationAbout(SymmetryAxis{axis.point_O, a, 0}, turn);
  }
  double worst = 0.0;
  for (const Eigen::Vector3d& x : model_points_O) {
    worst = std::max(worst, (T_est * x - e.T_symmetric * x).squaredNorm());
  }
  e.mssd_m = std::min(e.mssd_m, std::sqrt(worst));  // still the least over the symmetries tried
  e.rotation_rad = Eigen::AngleAxisd(e.T_symmetric.linear().transpose() * T_est.linear()).angle();
  e.translation_m = (T_est.translation() - e.T_symmetric.translation()).norm();
  return e;
}

}  // namespace uwscan::perception
