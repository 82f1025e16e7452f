#include "mapping/slam/registration_information.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>

#include "scanner/common/error.hpp"
#include "scanner/common/symmetrized.hpp"

namespace uwscan::mapping {
namespace {

// A weak direction whose normalised eigenvector lies at least this much in translation is a
// slide.
constexpr double kSlideShare = 0.9;

// The map N taking [w, v] about the target origin to normalised coordinates (rotation about the
// source's centroid in the target frame, scaled by its RMS radius): normalised = N^T info N.
Matrix6d Normaliser(const perception::PointCloud& source,
                    const Eigen::Isometry3d& T_target_source) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < source.size(); ++i) centroid += T_target_source * source.Point(i);
  centroid /= static_cast<double>(source.size());
  double radius2 = 0.0;
  for (std::size_t i = 0; i < source.size(); ++i) {
    radius2 += (T_target_source * source.Point(i) - centroid).squaredNorm();
  }
  const double radius = std::sqrt(radius2 / static_cast<double>(source.size()));
  // [w, v_origin] = A [w, v_centroid]: a rotation about the centroid moves the origin by -w x c.
  Matrix6d A = Matrix6d::Identity();
  Eigen::Matrix3d skew;
  skew << 0.0, -centroid.z(), centroid.y(), centroid.z(), 0.0, -centroid.x(), -centroid.y(),
      centroid.x(), 0.0;
  A.bottomLeftCorner<3, 3>() = skew;
  Matrix6d S = Matrix6d::Identity();
  S.topLeftCorner<3, 3>() /= std::max(radius, 1e-3);
  return A * S;
}

}  // namespace

KeptDirections WithoutWeakDirections(const Matrix6d& information,
                                     const perception::PointCloud& source,
                                     const Eigen::Isometry3d& T_target_source, double ratio) {
  const Matrix6d N = Normaliser(source, T_target_source);
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(N.transpose() * information * N);
  Vector6d values = eigen.eigenvalues();
  Vector6d inverse_values = Vector6d::Zero();
  for (int k = 0; k < 6; ++k) {
    if (!(values(k) > 0.0 && values(k) >= ratio * values(5))) values(k) = 0.0;
    if (values(k) > 0.0) inverse_values(k) = 1.0 / values(k);
  }
  KeptDirections out;
  out.count = static_cast<int>((values.array() > 0.0).count());
  const Matrix6d c = N * eigen.eigenvectors() * inverse_values.asDiagonal() *
                     eigen.eigenvectors().transpose() * N.transpose();
  out.covariance = Symmetrized(c);
  const Matrix6d N_inverse = N.inverse();
  const Matrix6d kept = N_inverse.transpose() * eigen.eigenvectors() * values.asDiagonal() *
                        eigen.eigenvectors().transpose() * N_inverse;
  // A slide along a pipe is a pure translation, but noise tilts its eigenvector by a few
  // milliradians per metre: what is left then measures a sliver of the slide, from the start
  // ICP was given, and over a dive that pulled the DVL's scale error off. Slides go exactly.
  Matrix6d P = Matrix6d::Identity();
  for (int k = 0; k < 6; ++k) {
    if (values(k) > 0.0 || eigen.eigenvectors().col(k).tail<3>().norm() < kSlideShare) continue;
    // The data's own translation (about its centroid): the same vector about any point, where
    // the eigenvector's translation about the target origin would carry its small turn times
    // the lever arm (about 20 mrad off the pipe on the pipe dive).
    Vector6d slide = Vector6d::Zero();
    slide.tail<3>() = eigen.eigenvectors().col(k).tail<3>();
    slide = P * slide;  // orthogonal to the slides already taken out (a bare seabed has two)
    if (slide.norm() < 1e-6) continue;
    slide.normalize();
    P -= slide * slide.transpose();
    out.slides.push_back(slide.tail<3>());
  }
  const Matrix6d projected = P * kept * P;
  out.information = Symmetrized(projected);
  return out;
}

int SurfaceDirections(const perception::PointCloud& cloud, double ratio) {
  if (cloud.empty()) return 0;
  if (!cloud.has_normals()) throw Error("SurfaceDirections: the cloud has no normals");
  Matrix6d information = Matrix6d::Zero();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p = cloud.Point(i);
    const Eigen::Vector3d n = cloud.normals[i].cast<double>();
    Vector6d row;
    row << p.cross(n), n;  // d(n . (R p + t)) / d[w, v]
    information.noalias() += row * row.transpose();
  }
  return WithoutWeakDirections(information, cloud, Eigen::Isometry3d::Identity(), ratio).count;
}

Matrix6d SlideCovariance(const std::vector<Eigen::Vector3d>& slides,
                         const Eigen::Isometry3d& T_target_source, double sigma_m) {
  Matrix6d covariance = Matrix6d::Zero();
  for (const Eigen::Vector3d& slide : slides) {
    const Eigen::Vector3d in_source = T_target_source.linear().transpose() * slide;
    covariance.bottomRightCorner<3, 3>() += sigma_m * sigma_m * in_source * in_source.transpose();
  }
  return covariance;
}

double Chi2Quantile999(int dof) {
  static constexpr std::array<double, 6> kQuantiles = {10.828, 13.816, 16.266,
                                                       18.467, 20.515, 22.458};
  return kQuantiles.at(static_cast<std::size_t>(std::clamp(dof, 1, 6) - 1));
}

}  // namespace uwscan::mapping
