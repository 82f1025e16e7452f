#include "mapping/slam/joint_pose_uncertainty.hpp"

#include <cholmod.h>

#include <Eigen/CholmodSupport>
#include <cmath>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {

// Made on the first covariance asked for: `map` keeps and writes the information, only `compare`
// solves with it. CHOLMOD's supernodal Cholesky: its solves take a batch of columns through dense
// blocks at once, where a simplicial factor walks its columns once per column solved.
struct JointPoseUncertainty::Factor {
  // A factor with the CHOLMOD workspace that goes with it. CHOLMOD does not say that two solves
  // may share a factor, so each thread solving at once takes a copy of its own.
  struct Solver {
    cholmod_common common{};
    cholmod_factor* factor = nullptr;
    Solver() {
      cholmod_start(&common);
      common.print = 0;  // a library never prints: a singular information is a value here
    }
    ~Solver() {
      if (factor) cholmod_free_factor(&factor, &common);
      cholmod_finish(&common);
    }
    Solver(const Solver&) = delete;
    Solver& operator=(const Solver&) = delete;
  };

  std::once_flag made;
  Solver first;  // the factorisation's
  bool positive_definite = false;
  std::mutex idle_lock;
  std::vector<std::unique_ptr<Solver>> idle;  // copies no solve is using

  void Make(const Eigen::SparseMatrix<double>& information) {
    cholmod_sparse a = Eigen::viewAsCholmod(information.selfadjointView<Eigen::Lower>());
    first.factor = cholmod_analyze(&a, &first.common);
    if (!first.factor) return;
    cholmod_factorize(&a, first.factor, &first.common);
    positive_definite = first.common.status == CHOLMOD_OK && first.factor->minor == first.factor->n;
  }

  // information^-1 * unit, or none when CHOLMOD cannot solve (out of memory).
  std::optional<Eigen::MatrixXd> Solve(Eigen::MatrixXd& unit) {
    std::unique_ptr<Solver> solver = Take();
    if (!solver->factor) return std::nullopt;
    cholmod_dense b = Eigen::viewAsCholmod(unit);
    cholmod_dense* x = cholmod_solve(CHOLMOD_A, solver->factor, &b, &solver->common);
    std::optional<Eigen::MatrixXd> out;
    if (x) {
      out = Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(x->x),
                                              static_cast<Eigen::Index>(x->nrow),
                                              static_cast<Eigen::Index>(x->ncol));
      cholmod_free_dense(&x, &solver->common);
    }
    const std::lock_guard lock(idle_lock);
    idle.push_back(std::move(solver));
    return out;
  }

  std::unique_ptr<Solver> Take() {
    const std::lock_guard lock(idle_lock);
    if (!idle.empty()) {
      std::unique_ptr<Solver> solver = std::move(idle.back());
      idle.pop_back();
      return solver;
    }
    auto solver = std::make_unique<Solver>();
    solver->factor = cholmod_copy_factor(first.factor, &solver->common);
    return solver;
  }
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
    if (information_.rows() > 0) factor_->Make(information_);
  });
  if (!factor_->positive_definite) return std::nullopt;
  const Eigen::Index m = 6 * std::ssize(poses);
  Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(information_.rows(), m);
  for (Eigen::Index k = 0; k < m; ++k)
    unit(pose_columns_[poses[static_cast<std::size_t>(k / 6)]] + k % 6, k) = 1.0;
  const std::optional<Eigen::MatrixXd> solved = factor_->Solve(unit);
  if (!solved) throw Error("joint pose uncertainty: CHOLMOD could not solve (out of memory?)");
  const Eigen::MatrixXd& columns = *solved;
  Eigen::MatrixXd out(6 * std::ssize(pose_columns_), m);
  for (std::size_t pose = 0; pose < pose_columns_.size(); ++pose)
    out.middleRows(6 * static_cast<Eigen::Index>(pose), 6) =
        columns.middleRows(pose_columns_[pose], 6);
  return out;
}

}  // namespace uwscan::mapping
