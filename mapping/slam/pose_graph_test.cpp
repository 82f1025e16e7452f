#include "mapping/slam/pose_graph.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "mapping/log/dive_log_test_support.hpp"
#include "mapping/slam/joint_pose_uncertainty.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping::test {
namespace {

TEST(PoseGraph, ACovarianceIsTheInverseOfItsOnlyPrior) {
  PoseGraph graph;
  const Eigen::Isometry3d T = TestPose(3);
  graph.AddNode(T);
  Matrix6d information = Matrix6d::Zero();
  information.diagonal() << 1e4, 4e4, 9e4, 1e2, 4e2,
      9e2;  // 0.01, 0.005, 0.0033 rad; 0.1, 0.05, 0.033 m
  information(0, 3) = information(3, 0) = 50.0;
  graph.AddPrior({.node = 0, .T_W_V = T, .information = information});
  graph.Solve({});
  const std::optional<std::vector<Matrix6d>> covariance = graph.Covariances();
  ASSERT_TRUE(covariance.has_value());
  EXPECT_LT(((*covariance)[0] - information.inverse()).norm(), 1e-9 * information.inverse().norm());
}

// Node 0 at the origin held by a prior, node 1 measured from it by one edge: to first order
// node 1's [w, v] is A (e_0 + e_edge) with A = [[I, 0], [-[t]x, I]] (a turn of node 0 swings
// node 1 about it), so its covariance is A (C_0 + C_edge) A^T and it shares A C_0 with node 0.
struct TwoNodeGraph {
  Eigen::Vector3d t{2.0, -1.0, 0.5};
  Matrix6d prior = Matrix6d::Zero(), edge = Matrix6d::Zero(), A = Matrix6d::Identity();
  PoseGraph graph;

  TwoNodeGraph() {
    Eigen::Isometry3d T_0_1 = Eigen::Isometry3d::Identity();
    T_0_1.linear() =
        Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    T_0_1.translation() = t;
    prior.diagonal() << 1e4, 2e4, 3e4, 1e3, 2e3, 5e3;
    prior(1, 4) = prior(4, 1) = 300.0;
    edge.diagonal() << 4e4, 1e4, 2e4, 3e3, 1e3, 2e3;
    edge(0, 5) = edge(5, 0) = -500.0;
    graph.AddNode(Eigen::Isometry3d::Identity());
    graph.AddNode(T_0_1);
    graph.AddPrior({.node = 0, .information = prior});
    graph.AddEdge({.from = 0, .to = 1, .T_from_to = T_0_1, .information = edge});
    graph.Solve({});
    A.block<3, 3>(3, 0) << 0.0, t.z(), -t.y(), -t.z(), 0.0, t.x(), t.y(), -t.x(), 0.0;  // -[t]x
  }
  Matrix6d C0() const { return prior.inverse(); }
  Matrix6d C1() const { return A * (prior.inverse() + edge.inverse()) * A.transpose(); }
  Matrix6d C10() const { return A * prior.inverse(); }
};

TEST(PoseGraph, ACovarianceCarriesThePriorAndTheEdgeAlongTheLever) {
  const TwoNodeGraph g;
  const std::optional<std::vector<Matrix6d>> covariance = g.graph.Covariances();
  ASSERT_TRUE(covariance.has_value());
  EXPECT_LT(((*covariance)[0] - g.C0()).norm(), 1e-9 * g.C0().norm());
  EXPECT_LT(((*covariance)[1] - g.C1()).norm(), 1e-9 * g.C1().norm()) << (*covariance)[1] << "\n\n"
                                                                      << g.C1();
}

// The same graph's joint covariance from its information: the rows in pose order, the columns in
// the order asked for.
TEST(PoseGraph, AJointCovarianceHoldsWhatTwoNodesShare) {
  const TwoNodeGraph g;
  const std::optional<Eigen::SparseMatrix<double>> information = g.graph.Information();
  ASSERT_TRUE(information.has_value());
  const JointPoseUncertainty uncertainty(*information, {0, 6});
  // Rows: poses 0 and 1 in order; columns: pose 1, then pose 0.
  const std::optional<Eigen::MatrixXd> joint = uncertainty.CovarianceColumns({1, 0});
  ASSERT_TRUE(joint.has_value());
  ASSERT_EQ(joint->rows(), 12);
  ASSERT_EQ(joint->cols(), 12);
  EXPECT_LT((joint->block<6, 6>(6, 0) - g.C1()).norm(), 1e-9 * g.C1().norm());
  EXPECT_LT((joint->block<6, 6>(0, 6) - g.C0()).norm(), 1e-9 * g.C0().norm());
  EXPECT_LT((joint->block<6, 6>(6, 6) - g.C10()).norm(), 1e-9 * g.C10().norm())
      << joint->block<6, 6>(6, 6) << "\n\n"
      << g.C10();
  EXPECT_LT((joint->block<6, 6>(0, 0) - g.C10().transpose()).norm(), 1e-9 * g.C10().norm());
}

TEST(PoseGraph, RecoversAChainFromExactEdgesAndAPrior) {
  PoseGraph graph;
  std::vector<Eigen::Isometry3d> truth;
  for (int i = 0; i < 5; ++i) truth.push_back(TestPose(10 + static_cast<std::uint64_t>(i)));
  for (int i = 0; i < 5; ++i)
    graph.AddNode(i == 0 ? truth[0] : TestPose(100 + static_cast<std::uint64_t>(i)));
  graph.AddPrior({.node = 0, .T_W_V = truth[0], .information = Matrix6d::Identity() * 1e6});
  for (int i = 0; i + 1 < 5; ++i) {
    graph.AddEdge(
        {.from = i,
         .to = i + 1,
         .T_from_to = truth[static_cast<size_t>(i)].inverse() * truth[static_cast<size_t>(i) + 1],
         .information = Matrix6d::Identity() * 1e4});
  }
  EXPECT_TRUE(graph.Solve({}).converged);
  for (int i = 0; i < 5; ++i) {
    EXPECT_LT(PoseError(graph.pose(i), truth[static_cast<size_t>(i)]).norm(), 1e-7) << "node " << i;
  }
}

// A chain of n nodes from TestPose truths, node 0 held by a prior, each edge exact; the nodes
// start at other poses.
PoseGraph ExactChain(int n, std::vector<Eigen::Isometry3d>* truth) {
  PoseGraph graph;
  for (int i = 0; i < n; ++i) truth->push_back(TestPose(10 + static_cast<std::uint64_t>(i)));
  for (int i = 0; i < n; ++i)
    graph.AddNode(i == 0 ? (*truth)[0] : TestPose(100 + static_cast<std::uint64_t>(i)));
  graph.AddPrior({.node = 0, .T_W_V = (*truth)[0], .information = Matrix6d::Identity() * 1e6});
  for (int i = 0; i + 1 < n; ++i) {
    const auto a = static_cast<size_t>(i);
    graph.AddEdge({.from = i,
                   .to = i + 1,
                   .T_from_to = (*truth)[a].inverse() * (*truth)[a + 1],
                   .information = Matrix6d::Identity() * 1e4});
  }
  return graph;
}

void ExpectSameBits(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, int node) {
  for (int k = 0; k < 16; ++k) {
    EXPECT_EQ(std::bit_cast<std::uint64_t>(a.matrix()(k)),
              std::bit_cast<std::uint64_t>(b.matrix()(k)))
        << "node " << node;
  }
}

TEST(PoseGraph, AWindowSolveMovesOnlyItsNodesAndFindsThemFromTheHeldOnes) {
  std::vector<Eigen::Isometry3d> truth;
  PoseGraph graph = ExactChain(8, &truth);
  // The held nodes at their truth, the free ones 0.2 m and 0.1 rad off theirs.
  Eigen::Isometry3d off = Eigen::Isometry3d::Identity();
  off.linear() = Eigen::AngleAxisd(0.1, Eigen::Vector3d(1, -2, 1).normalized()).toRotationMatrix();
  off.translation() = Eigen::Vector3d(0.1, -0.1, 0.14);
  for (int i = 1; i < 8; ++i)
    graph.set_pose(i,
                   truth[static_cast<size_t>(i)] * (i < 5 ? Eigen::Isometry3d::Identity() : off));
  std::vector<Eigen::Isometry3d> before;
  for (int i = 0; i < 8; ++i) before.push_back(graph.pose(i));
  EXPECT_TRUE(graph.SolveWindow(5, {}).converged);
  for (int i = 0; i < 5; ++i) ExpectSameBits(graph.pose(i), before[static_cast<size_t>(i)], i);
  for (int i = 5; i < 8; ++i)
    EXPECT_LT(PoseError(graph.pose(i), truth[static_cast<size_t>(i)]).norm(), 1e-7) << "node " << i;
}

TEST(PoseGraph, AWindowSolveHoldsWhatIsBeforeItEvenWhenItIsWrong) {
  // Node 2 is held 0.1 m off its truth: the free nodes follow it, as the exact edges say.
  std::vector<Eigen::Isometry3d> truth;
  PoseGraph graph = ExactChain(5, &truth);
  Eigen::Isometry3d shifted = truth[2];
  shifted.translation().x() += 0.1;
  graph.set_pose(0, truth[0]);
  graph.set_pose(1, truth[1]);
  graph.set_pose(2, shifted);
  const Eigen::Isometry3d held = graph.pose(2);
  graph.SolveWindow(3, {});
  ExpectSameBits(graph.pose(2), held, 2);
  const Eigen::Isometry3d expected_3 = shifted * (truth[2].inverse() * truth[3]);
  EXPECT_LT(PoseError(graph.pose(3), expected_3).norm(), 1e-6);
  // The whole solve then spreads the error over the chain instead.
  graph.Solve({});
  EXPECT_LT(PoseError(graph.pose(4), truth[4]).norm(), 1e-6);
}

TEST(PoseGraph, AWindowSolveCostsWhatTheWindowHoldsWhateverTheGraphsSize) {
  for (const int n : {20, 2000}) {
    std::vector<Eigen::Isometry3d> truth;
    PoseGraph graph = ExactChain(n, &truth);
    // The last 4 nodes: their 3 edges among them, and the one from the held node before them.
    EXPECT_EQ(graph.SolveWindow(n - 4, {}).measurements, 4) << n << " nodes";
    EXPECT_EQ(graph.Solve({.max_iterations = 1}).measurements, n) << n << " nodes";
  }
}

TEST(PoseGraph, AWindowSolveHoldsTheDeadReckoningsCalibration) {
  PoseGraph graph;
  graph.EstimateDeadReckoningCalibration(0.01, 0.01);
  graph.AddNode(Eigen::Isometry3d::Identity());
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
  far.translation() = Eigen::Vector3d(10.0, 0.0, 0.0);
  graph.AddNode(far);
  graph.AddNode(far);
  graph.AddPrior({.node = 0, .information = Matrix6d::Identity() * 1e6});
  // The dead reckoning says 10 m, an exact edge 10.2 m: a whole solve puts 2 % into the scale.
  graph.AddEdge({.from = 0,
                 .to = 1,
                 .T_from_to = far,
                 .information = Matrix6d::Identity() * 1e2,
                 .dead_reckoned = true});
  Eigen::Isometry3d measured = far;
  measured.translation().x() = 10.2;
  graph.AddEdge(
      {.from = 0, .to = 2, .T_from_to = measured, .information = Matrix6d::Identity() * 1e6});
  graph.AddEdge({.from = 1, .to = 2, .information = Matrix6d::Identity() * 1e6});
  graph.SolveWindow(1, {});
  EXPECT_EQ(graph.calibration().scale_error, 0.0);
  graph.Solve({});
  EXPECT_GT(std::abs(graph.calibration().scale_error), 0.005);
}

TEST(PoseGraph, AWindowOutsideTheGraphIsRefused) {
  std::vector<Eigen::Isometry3d> truth;
  PoseGraph graph = ExactChain(3, &truth);
  EXPECT_THROW(graph.SolveWindow(3, {}), Error);
  EXPECT_THROW(graph.SolveWindow(-1, {}), Error);
}

}  // namespace
}  // namespace uwscan::mapping::test
