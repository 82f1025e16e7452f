#include "mapping/slam/joint_pose_uncertainty.hpp"

#include <Eigen/SparseCholesky>
#include <cmath>
#include <string>
#include <utility>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {

struct JointPoseUncertainty::Factor {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  bool positive_definite = false;
};

JointPoseUncertainty::JointPoseUncertainty(Eigen::SparseMatrix<double> information,
                                           std::vector<int> pose_columns)
    : pose_columns_(std::move(pose_columns)), factor_(std::make_unique<Factor>()) {
  information_.swap(information);  // Eigen 3.4's SparseMatrix has no move constructor
  if (information_.rows() != information_.cols())
    throw Error("joint pose uncertainty: the information is not square");
  for (Eigen::Index k = 0; k < information_.nonZeros(); ++k) {
    if (!std::isfinite(information_.valuePtr()[k]))
      throw Error("joint pose uncertainty: the information holds a value that is not finite");
  }
  for (const int column : pose_columns_) {
    if (column < 0 || column + 6 > information_.rows()) {
      throw Error("joint pose uncertainty: a pose's columns start at " + std::to_string(column) +
                  ", outside the information's " + std::to_string(information_.rows()));
    }
  }
  if (information_.rows() == 0) return;
  factor_->ldlt.compute(information_);
  factor_->positive_definite =
      factor_->ldlt.info() == Eigen::Success && (factor_->ldlt.vectorD().array() > 0.0).all();
}

JointPoseUncertainty::~JointPoseUncertainty() = default;

std::optional<Eigen::MatrixXd> JointPoseUncertainty::Covariance(
    const std::vector<std::size_t>& poses) const {
  std::vector<Eigen::Index> index;
  for (const std::size_t pose : poses) {
    if (pose >= pose_columns_.size()) {
      throw Error("joint pose uncertainty: no pose " + std::to_string(pose) + " of " +
                  std::to_string(pose_columns_.size()));
    }
    for (int k = 0; k < 6; ++k) index.push_back(pose_columns_[pose] + k);
  }
  if (!factor_->positive_definite) return std::nullopt;
  // The inverse's columns for the poses, one solve each, then their rows.
  const Eigen::Index m = std::ssize(index);
  Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(information_.rows(), m);
  for (Eigen::Index k = 0; k < m; ++k) unit(index[static_cast<std::size_t>(k)], k) = 1.0;
  const Eigen::MatrixXd columns = factor_->ldlt.solve(unit);
  Eigen::MatrixXd joint(m, m);
  for (Eigen::Index r = 0; r < m; ++r)
    joint.row(r) = columns.row(index[static_cast<std::size_t>(r)]);
  return Eigen::MatrixXd(0.5 * (joint + joint.transpose()));
}

}  // namespace uwscan::mapping
