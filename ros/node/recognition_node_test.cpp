#include "ros/node/recognition_node.hpp"

#include <gtest/gtest.h>

#include <random>

#include "scanner/common/random_draws.hpp"

namespace uwscan::ros {
namespace {

// [position of the object's origin; rotation vector about the scan's axes] of T_S_O moved by
// recognition's perturbation [w; v] (x -> x + w x (x - c) + v in the object frame, exactly: a
// rotation by |w| about c, then v).
Eigen::Matrix<double, 6, 1> Perturbed(const Eigen::Isometry3d& T_S_O, const Eigen::Vector3d& c,
                                      const Eigen::Matrix<double, 6, 1>& wv) {
  const Eigen::Vector3d w = wv.head<3>(), v = wv.tail<3>();
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
  if (w.norm() > 0) delta.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  delta.translation() = c - delta.linear() * c + v;
  const Eigen::Isometry3d moved = T_S_O * delta;
  Eigen::Matrix<double, 6, 1> out;
  out.head<3>() = moved.translation() - T_S_O.translation();
  const Eigen::AngleAxisd turn(moved.rotation() * T_S_O.rotation().transpose());
  out.tail<3>() = turn.angle() * turn.axis();
  return out;
}

TEST(ObjectPoseCovariance, IsTheFirstOrderPropagationOfTheObjectFramePerturbation) {
  std::mt19937 rng(5);
  std::normal_distribution<double> d(0.0, 1.0);
  Eigen::Isometry3d T_S_O = Eigen::Isometry3d::Identity();
  T_S_O.linear() = DrawRotation(rng).toRotationMatrix();
  T_S_O.translation() = DrawVector3(d, rng);
  const Eigen::Vector3d c = 0.2 * DrawVector3(d, rng);
  // The Jacobian by central differences, column by column.
  Eigen::Matrix<double, 6, 6> J;
  const double h = 1e-6;
  for (int k = 0; k < 6; ++k) {
    Eigen::Matrix<double, 6, 1> e = Eigen::Matrix<double, 6, 1>::Zero();
    e(k) = h;
    J.col(k) = (Perturbed(T_S_O, c, e) - Perturbed(T_S_O, c, -e)) / (2 * h);
  }
  Eigen::Matrix<double, 6, 6> A;
  for (int r = 0; r < 6; ++r) {
    for (int k = 0; k < 6; ++k) A(r, k) = d(rng);
  }
  const Eigen::Matrix<double, 6, 6> C = A * A.transpose() * 1e-4;
  const Covariance6d expected = J * C * J.transpose();
  EXPECT_LT((ObjectPoseCovariance(T_S_O, c, C) - expected).norm(), 1e-8 * expected.norm());
}

}  // namespace
}  // namespace uwscan::ros
