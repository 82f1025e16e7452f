#include "mapping/slam/joint_pose_uncertainty.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <random>
#include <thread>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

// A random symmetric positive definite information of `nodes` nodes, 6 rows each, coupled only
// between neighbouring nodes (a chain, sparse as a pose graph's).
Eigen::SparseMatrix<double> ChainInformation(int nodes, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::MatrixXd root = Eigen::MatrixXd::Zero(6 * nodes, 6 * nodes);
  for (int r = 0; r < 6 * nodes; ++r)
    for (int c = std::max(0, r - 11); c <= r; ++c) root(r, c) = uniform(random);
  root.diagonal().array() += 4.0;
  return Eigen::MatrixXd(root * root.transpose()).sparseView();
}

// Every pose's columns, asked in any order and from several threads at once, are those of the
// dense inverse.
TEST(JointPoseUncertainty, ColumnsAreThoseOfTheInverseFromEveryThread) {
  const Eigen::SparseMatrix<double> information = ChainInformation(40, 3);
  std::vector<int> columns;
  for (int node = 39; node >= 0; node -= 2) columns.push_back(6 * node);  // every other node
  const JointPoseUncertainty uncertainty(information, columns);
  const Eigen::MatrixXd inverse = Eigen::MatrixXd(information).inverse();
  std::vector<std::optional<Eigen::MatrixXd>> solved(4);
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < solved.size(); ++t)
    threads.emplace_back([&, t] { solved[t] = uncertainty.CovarianceColumns({t, 19 - t, 7}); });
  for (std::thread& thread : threads) thread.join();
  for (std::size_t t = 0; t < solved.size(); ++t) {
    ASSERT_TRUE(solved[t]);
    const std::vector<std::size_t> asked = {t, 19 - t, 7};
    for (std::size_t k = 0; k < asked.size(); ++k) {
      for (std::size_t pose = 0; pose < columns.size(); ++pose) {
        const Eigen::MatrixXd expected = inverse.block(columns[pose], columns[asked[k]], 6, 6);
        const Eigen::MatrixXd got = solved[t]->block(6 * static_cast<Eigen::Index>(pose),
                                                     6 * static_cast<Eigen::Index>(k), 6, 6);
        EXPECT_LT((got - expected).norm(), 1e-10 * (1.0 + expected.norm()))
            << "pose " << pose << " with pose " << asked[k];
      }
    }
  }
}

// A direction nothing constrains: no covariance, said as a value (and nothing printed).
TEST(JointPoseUncertainty, ASingularInformationGivesNone) {
  Eigen::SparseMatrix<double> information = ChainInformation(3, 5);
  for (Eigen::Index k = 0; k < information.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(information, k); it; ++it)
      if (it.row() == 7 || it.col() == 7) it.valueRef() = 0.0;
  const JointPoseUncertainty uncertainty(information, {0, 6, 12});
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  EXPECT_FALSE(uncertainty.CovarianceColumns({0}));
  EXPECT_EQ(testing::internal::GetCapturedStdout(), "");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  EXPECT_THROW(uncertainty.CovarianceColumns({3}), Error);
}

}  // namespace
}  // namespace uwscan::mapping
