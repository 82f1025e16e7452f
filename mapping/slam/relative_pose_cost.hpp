#pragma once

#include <ceres/sized_cost_function.h>

#include <Eigen/Geometry>

#include "mapping/slam/dead_reckoning_calibration.hpp"
#include "mapping/slam/pose_graph.hpp"

// The pose graph's edge between two nodes, with its Jacobians written out: it is nearly every
// residual block of a dive's graph, and Ceres's automatic differentiation of it (14 dual numbers
// through the quaternion algebra and the 6x6 whitening) was half of a window solve's time
// (bench/slam/RESULTS.md, "Edges with analytic Jacobians").
namespace uwscan::mapping {

// The measured motion T_a_b of an edge and the square root of its information.
struct RelativePoseMeasurement {
  Eigen::Quaterniond q_meas;
  Eigen::Vector3d t_meas;
  Matrix6d sqrt_information;
};

// Residual sqrt(L) e of a relative pose measurement between nodes a and b, each a quaternion
// (x, y, z, w as Eigen stores it) and a position in the world frame: e = [2 vec(q_d), t_hat -
// q_d t_meas], q_d = (q_a^-1 q_b) q_meas^-1 taken with w >= 0 (the short way round), t_hat =
// q_a^-1 (p_b - p_a). Jacobians in the quaternions' coordinates are those of the residual made
// independent of the quaternions' norm (zero along the quaternion itself): with any manifold of
// unit quaternions their product with its Plus Jacobian is the derivative along the manifold.
// Parameter blocks: q_a (4), p_a (3), q_b (4), p_b (3).
class RelativePoseCost final : public ceres::SizedCostFunction<6, 4, 3, 4, 3> {
 public:
  explicit RelativePoseCost(const RelativePoseMeasurement& measurement)
      : measurement_(measurement) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  RelativePoseMeasurement measurement_;
};

// A dead-reckoned motion: as RelativePoseCost, its measured translation made true by the
// calibration [scale error, misalignment] first (DeadReckoningCalibration::Correct), a fifth
// parameter block (2).
class DeadReckonedPoseCost final : public ceres::SizedCostFunction<6, 4, 3, 4, 3, 2> {
 public:
  explicit DeadReckonedPoseCost(const RelativePoseMeasurement& measurement)
      : measurement_(measurement) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  RelativePoseMeasurement measurement_;
};

}  // namespace uwscan::mapping
