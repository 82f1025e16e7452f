#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <optional>
#include <vector>

// How well a pose graph's poses are placed relative to each other, for a dive of any length.
namespace uwscan::mapping {

// A pose graph's information J^T J (sparse: its size grows with the dive, not its square), from
// which the joint covariance of any few poses is computed when asked: the cross terms the
// marginal covariances lack, which say how well two poses are placed against each other (two legs
// of a dive tied by a loop closure are placed alike even where both have drifted).
//
// The information's rows and columns are 6 per graph node, [rotation (rad, about the world
// axes), position (m)] as the graph's covariances are, then any other parameter the graph
// estimates; a pose is the node whose 6 columns start at its `pose_columns` entry.
class JointPoseUncertainty {
 public:
  // Throws uwscan::Error when the information is not square, not finite, or a pose's columns lie
  // outside it.
  JointPoseUncertainty(Eigen::SparseMatrix<double> information, std::vector<int> pose_columns);
  ~JointPoseUncertainty();

  std::size_t pose_count() const { return pose_columns_.size(); }
  const Eigen::SparseMatrix<double>& information() const { return information_; }
  const std::vector<int>& pose_columns() const { return pose_columns_; }

  // The covariance of every pose with the given ones: 6 rows per pose of the graph, in order, by
  // 6 columns per given pose, each [rotation (rad), position (m)]. One sparse solve per column
  // (the information factored, CHOLMOD's sparse Cholesky, on the first call). std::nullopt when the
  // information is singular (a direction nothing constrains). Throws uwscan::Error for a pose
  // outside [0, pose_count()). Safe to call from several threads at once.
  std::optional<Eigen::MatrixXd> CovarianceColumns(const std::vector<std::size_t>& poses) const;

 private:
  struct Factor;
  Eigen::SparseMatrix<double> information_;
  std::vector<int> pose_columns_;
  std::unique_ptr<Factor> factor_;
};

}  // namespace uwscan::mapping
