#include "mapping/slam/inverse_blocks.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

// A pose-graph-like information: 6x6 blocks on a chain of `nodes`, a few chords (loops), and
// every block made positive definite by a random Gram matrix.
Eigen::SparseMatrix<double> GraphInformation(int nodes, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  std::uniform_int_distribution<int> pick(0, nodes - 1);
  const int n = 6 * nodes;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(n, n);
  auto add_edge = [&](int a, int b) {
    // A relative measurement, 6 residuals A (x_a - x_b): J^T J over the two nodes' 12 columns.
    // Like a pose graph's edges, it says nothing about moving every node together.
    Eigen::MatrixXd A(6, 6);
    for (int i = 0; i < 36; ++i) A(i) = normal(rng);
    Eigen::MatrixXd J(6, 12);
    J << A, -A;
    const Eigen::MatrixXd H = J.transpose() * J;
    const int at[2] = {6 * a, 6 * b};
    for (int i = 0; i < 2; ++i) {
      for (int k = 0; k < 2; ++k) dense.block(at[i], at[k], 6, 6) += H.block(6 * i, 6 * k, 6, 6);
    }
  };
  for (int i = 0; i + 1 < nodes; ++i) add_edge(i, i + 1);
  for (int c = 0; c < nodes / 3; ++c) {
    const int a = pick(rng), b = pick(rng);
    if (a != b) add_edge(a, b);
  }
  dense.block(0, 0, 6, 6) += Eigen::MatrixXd::Identity(6, 6);  // the prior that fixes the gauge
  return dense.sparseView();
}

TEST(InverseBlocks, EqualTheDenseInverseOnAGraphWithLoops) {
  const int nodes = 40;
  const Eigen::SparseMatrix<double> H = GraphInformation(nodes, 7);
  const Eigen::MatrixXd reference = Eigen::MatrixXd(H).inverse();
  std::vector<IndexRange> blocks;
  for (int i = nodes - 1; i >= 0; i -= 3) blocks.push_back({6 * i, 6});
  blocks.push_back({3, 9});  // across two nodes
  const std::optional<std::vector<Eigen::MatrixXd>> got = InverseBlocks(H, blocks);
  ASSERT_TRUE(got.has_value());
  ASSERT_EQ(got->size(), blocks.size());
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const Eigen::MatrixXd expected =
        reference.block(blocks[k].start, blocks[k].start, blocks[k].size, blocks[k].size);
    EXPECT_LT(((*got)[k] - expected).norm(), 1e-9 * expected.norm()) << "block " << k;
  }
}

// The recursion's sums are taken term by term in the order the header's formula writes them,
// whatever way the implementation finds the terms: its answers equal, to the bit, the recursion
// evaluated on a dense Z.
TEST(InverseBlocks, EqualTheRecursionSummedTermByTermToTheBit) {
  const int nodes = 60;
  const Eigen::SparseMatrix<double> H = GraphInformation(nodes, 11);
  const int n = 6 * nodes;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt(H);
  ASSERT_EQ(ldlt.info(), Eigen::Success);
  const Eigen::SparseMatrix<double>& L = ldlt.matrixL().nestedExpression();
  const Eigen::VectorXd d = ldlt.vectorD();
  Eigen::MatrixXd Z = Eigen::MatrixXd::Zero(n, n);
  for (int j = n - 1; j >= 0; --j) {
    std::vector<std::pair<int, double>> column;  // (row, L(row, j)), rows below j ascending
    for (Eigen::SparseMatrix<double>::InnerIterator it(L, j); it; ++it) {
      if (it.row() > j) column.emplace_back(static_cast<int>(it.row()), it.value());
    }
    std::sort(column.begin(), column.end());
    for (const auto& [i, l_ij] : column) {
      double sum = 0.0;
      for (const auto& [k, l_kj] : column) sum += Z(i, k) * l_kj;
      Z(i, j) = Z(j, i) = -sum;
    }
    double sum = 0.0;
    for (const auto& [i, l_ij] : column) sum += Z(i, j) * l_ij;
    Z(j, j) = 1.0 / d[j] - sum;
  }
  std::vector<IndexRange> blocks;
  for (int i = 0; i < nodes; ++i) blocks.push_back({6 * i, 6});
  const std::optional<std::vector<Eigen::MatrixXd>> got = InverseBlocks(H, blocks);
  ASSERT_TRUE(got.has_value());
  const auto& perm = ldlt.permutationP().indices();
  for (int b = 0; b < nodes; ++b) {
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c)
        ASSERT_EQ((*got)[b](r, c), Z(perm[6 * b + r], perm[6 * b + c])) << b << " " << r << c;
    }
  }
}

TEST(InverseBlocks, RefuseAMatrixWithAnUnconstrainedDirection) {
  Eigen::SparseMatrix<double> H = GraphInformation(10, 5);
  // Drop the prior: the chain's edges say nothing about where the whole graph is.
  for (int i = 0; i < 6; ++i) H.coeffRef(i, i) -= 1.0;
  const Eigen::MatrixXd dense(H);
  ASSERT_LT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(dense).eigenvalues().minCoeff(), 1e-9);
  EXPECT_FALSE(InverseBlocks(H, {{0, 6}}).has_value());

  // The same on a graph of 500 nodes, whose rounding is larger.
  Eigen::SparseMatrix<double> large = GraphInformation(500, 9);
  for (int i = 0; i < 6; ++i) large.coeffRef(i, i) -= 1.0;
  EXPECT_FALSE(InverseBlocks(large, {{0, 6}, {2994, 6}}).has_value());
  large.coeffRef(2994, 2994) += 1e-3;  // a weak prior on one coordinate of the last node
  EXPECT_FALSE(InverseBlocks(large, {{0, 6}}).has_value()) << "five directions are still free";

  Eigen::SparseMatrix<double> negative = GraphInformation(4, 1);
  negative.coeffRef(10, 10) = -1.0;
  EXPECT_FALSE(InverseBlocks(negative, {{6, 6}}).has_value());
}

TEST(InverseBlocks, ABlockOutsideTheMatrixIsAnError) {
  const Eigen::SparseMatrix<double> H = GraphInformation(3, 2);
  EXPECT_THROW(InverseBlocks(H, {{12, 7}}), Error);
  EXPECT_THROW(InverseBlocks(H, {{-1, 2}}), Error);
}

}  // namespace
}  // namespace uwscan::mapping
