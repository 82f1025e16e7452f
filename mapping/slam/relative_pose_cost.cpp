#include "mapping/slam/relative_pose_cost.hpp"

#include <cmath>

namespace uwscan::mapping {
namespace {

using Matrix63 = Eigen::Matrix<double, 6, 3>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d s;
  s << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return s;
}

// An edge's error and its derivatives along the nodes' rotations, each perturbed on the left in
// the world frame (q -> [1, delta] q, a turn of 2 |delta|), and along their positions.
struct EdgeError {
  Vector6d e;
  Matrix63 d_rotation_a, d_rotation_b;
  Eigen::Matrix3d R_a_transpose;  // d e_t / d p_b; its negative d e_t / d p_a
  Eigen::Matrix3d R_d;            // the rotation q_d: turns the measured translation
};

EdgeError ErrorOf(const double* const* parameters, const Eigen::Quaterniond& q_meas,
                  const Eigen::Vector3d& t_meas) {
  const Eigen::Map<const Eigen::Quaterniond> q_a(parameters[0]), q_b(parameters[2]);
  const Eigen::Map<const Eigen::Vector3d> p_a(parameters[1]), p_b(parameters[3]);
  const Eigen::Quaterniond q_a_inverse = q_a.conjugate();
  Eigen::Quaterniond q_d = (q_a_inverse * q_b) * q_meas.conjugate();
  // q and -q are the same rotation: take the one with w >= 0, so the error is the short way.
  if (q_d.w() < 0.0) q_d.coeffs() = -q_d.coeffs();
  const Eigen::Vector3d moved = p_b - p_a;
  const Eigen::Vector3d t_turned = q_d * t_meas;
  EdgeError error;
  error.e << 2.0 * q_d.vec(), q_a_inverse * moved - t_turned;
  error.R_a_transpose = q_a_inverse.toRotationMatrix();
  error.R_d = q_d.toRotationMatrix();
  // Both nodes turn q_d on the left by [1, u]: u = R_a^T delta_b for b, -R_a^T delta_a for a.
  // Then vec(q_d) moves by (w I - [v]x) u and q_d t_meas by 2 u x (q_d t_meas).
  Matrix63 d_u;
  d_u << 2.0 * (q_d.w() * Eigen::Matrix3d::Identity() - Skew(q_d.vec())), 2.0 * Skew(t_turned);
  error.d_rotation_b = d_u * error.R_a_transpose;
  error.d_rotation_a = -error.d_rotation_b;
  // And a's turn moves t_hat = R_a^T (p_b - p_a) by 2 R_a^T [p_b - p_a]x delta_a.
  error.d_rotation_a.bottomRows<3>() += 2.0 * error.R_a_transpose * Skew(moved);
  return error;
}

// The derivative in a quaternion's four coordinates whose product with [1, delta] q's
// derivative, P = [w I - [v]x; -v^T], is `d_tangent`, and which is zero along q itself (P^T P =
// I and P^T q = 0 for a unit q).
void WriteQuaternionJacobian(const Matrix6d& sqrt_information, const Matrix63& d_tangent,
                             const double* q_raw, double* jacobian) {
  const Eigen::Map<const Eigen::Quaterniond> q(q_raw);
  Eigen::Matrix<double, 3, 4> P_transpose;
  P_transpose << q.w() * Eigen::Matrix3d::Identity() + Skew(q.vec()), -q.vec();
  Eigen::Map<Eigen::Matrix<double, 6, 4, Eigen::RowMajor>> out(jacobian);
  out = sqrt_information * d_tangent * P_transpose;
}

void WritePositionJacobian(const Matrix6d& sqrt_information, const Eigen::Matrix3d& d_position,
                           double* jacobian) {
  Eigen::Map<Eigen::Matrix<double, 6, 3, Eigen::RowMajor>> out(jacobian);
  out = sqrt_information.rightCols<3>() * d_position;
}

// Residual and the four nodes' Jacobians (those asked for) of an edge's error.
void WriteEdge(const RelativePoseMeasurement& m, const EdgeError& error,
               double const* const* parameters, double* residuals, double** jacobians) {
  Eigen::Map<Vector6d> residual(residuals);
  residual = m.sqrt_information * error.e;
  if (jacobians == nullptr) return;
  if (jacobians[0] != nullptr)
    WriteQuaternionJacobian(m.sqrt_information, error.d_rotation_a, parameters[0], jacobians[0]);
  if (jacobians[1] != nullptr)
    WritePositionJacobian(m.sqrt_information, -error.R_a_transpose, jacobians[1]);
  if (jacobians[2] != nullptr)
    WriteQuaternionJacobian(m.sqrt_information, error.d_rotation_b, parameters[2], jacobians[2]);
  if (jacobians[3] != nullptr)
    WritePositionJacobian(m.sqrt_information, error.R_a_transpose, jacobians[3]);
}

}  // namespace

bool RelativePoseCost::Evaluate(double const* const* parameters, double* residuals,
                                double** jacobians) const {
  WriteEdge(measurement_, ErrorOf(parameters, measurement_.q_meas, measurement_.t_meas), parameters,
            residuals, jacobians);
  return true;
}

bool DeadReckonedPoseCost::Evaluate(double const* const* parameters, double* residuals,
                                    double** jacobians) const {
  const double scale_error = parameters[4][0], misalignment_rad = parameters[4][1];
  const Eigen::Vector3d t_true =
      DeadReckoningCalibration::Correct<double>(measurement_.t_meas, scale_error, misalignment_rad);
  const EdgeError error = ErrorOf(parameters, measurement_.q_meas, t_true);
  WriteEdge(measurement_, error, parameters, residuals, jacobians);
  if (jacobians == nullptr || jacobians[4] == nullptr) return true;
  // d t_true / d [scale error, misalignment]: t_true's horizontal part is the measured one turned
  // back by the misalignment, over (1 + scale error).
  const double inverse_scale = 1.0 / (1.0 + scale_error);
  const double x = measurement_.t_meas.x(), y = measurement_.t_meas.y();
  const double c = std::cos(misalignment_rad), s = std::sin(misalignment_rad);
  Eigen::Matrix<double, 3, 2> d_t_true;
  d_t_true << -inverse_scale * t_true.x(), inverse_scale * (-s * x + c * y),
      -inverse_scale * t_true.y(), -inverse_scale * (c * x + s * y), 0.0, 0.0;
  Eigen::Map<Eigen::Matrix<double, 6, 2, Eigen::RowMajor>> d_calibration(jacobians[4]);
  d_calibration = measurement_.sqrt_information.rightCols<3>() * (-error.R_d * d_t_true);
  return true;
}

}  // namespace uwscan::mapping
