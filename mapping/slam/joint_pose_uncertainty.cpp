#include "mapping/slam/joint_pose_uncertainty.hpp"

#include <Eigen/SparseCholesky>
#include <cmath>
#include <mutex>
#include <string>
#include <utility>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {

// Made on the first covariance asked for: `map` keeps and writes the information, only `compare`
// solves with it.
struct JointPoseUncertainty::Factor {
  std::once_flag made;
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
}

JointPoseUncertainty::~JointPoseUncertainty() = default;

std::optional<Eigen::MatrixXd> JointPoseUncertainty::CovarianceColumns(
    const std::vector<std::size_t>& poses) const {
  for (const std::size_t pose : poses) {
    if (pose >= pose_columns_.size()) {
      throw Error("joint pose uncertainty: no pose " + std::to_string(pose) + " of " +
                  std::to_string(pose_columns_.size()));
    }
  }
  std::call_once(factor_->made, [this] {
    if (information_.rows() == 0) return;
    factor_->ldlt.compute(information_);
    factor_->positive_definite =
        factor_->ldlt.info() == Eigen::Success && (factor_->ldlt.vectorD().array() > 0.0).all();
  });
  if (!factor_->positive_definite) return std::nullopt;
  const Eigen::Index m = 6 * std::ssize(poses);
  Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(information_.rows(), m);
  for (Eigen::Index k = 0; k < m; ++k)
    unit(pose_columns_[poses[static_cast<std::size_t>(k / 6)]] + k % 6, k) = 1.0;
  const Eigen::MatrixXd columns = factor_->ldlt.solve(unit);
  Eigen::MatrixXd out(6 * std::ssize(pose_columns_), m);
  for (std::size_t pose = 0; pose < pose_columns_.size(); ++pose)
    out.middleRows(6 * static_cast<Eigen::Index>(pose), 6) =
        columns.middleRows(pose_columns_[pose], 6);
  return out;
}

}  // namespace uwscan::mapping
