#include "mapping/slam/pose_graph.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <random>
#include <string>
#include <thread>
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

// A dive's graph grown node by node: noisy dead-reckoned motions (the calibration estimated),
// depth and roll/pitch priors on every node, and from node 150 on, every 7th node tied by a
// robust edge to the node 150 before it (a loop).
class GrowingGraph {
 public:
  explicit GrowingGraph(PoseGraph* graph) : graph_(graph) {
    graph_->EstimateDeadReckoningCalibration(0.01, 0.01);
  }
  void AddNode(int i) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(i));
    std::normal_distribution<double> noise(0.0, 1e-3);
    graph_->AddNode(Truth(i) * Noisy(&rng, &noise, 20.0));
    if (i == 0) {
      graph_->AddPrior({.node = 0, .T_W_V = Truth(0), .information = Matrix6d::Identity() * 1e6});
    } else {
      AddMeasuredEdge(i - 1, i, &rng, &noise, false);
    }
    if (i >= 150 && i % 7 == 0) AddMeasuredEdge(i - 150, i, &rng, &noise, true);
    graph_->AddDepth({.node = i, .z_m = Truth(i).translation().z() + noise(rng), .sigma_m = 1e-3});
    graph_->AddGravity({.node = i,
                        .down_in_V = Truth(i).linear().transpose() * Eigen::Vector3d::UnitZ(),
                        .sigma_rad = 1e-3});
  }

 private:
  static Eigen::Isometry3d Truth(int i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::AngleAxisd(0.002 * i, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T.translation() = Eigen::Vector3d(0.1 * i, 5.0 * std::sin(0.01 * i), 10.0);
    return T;
  }
  static Eigen::Isometry3d Noisy(std::mt19937_64* rng, std::normal_distribution<double>* noise,
                                 double scale) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d w(scale * (*noise)(*rng), scale * (*noise)(*rng), scale * (*noise)(*rng));
    T.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
    T.translation() = scale * Eigen::Vector3d((*noise)(*rng), (*noise)(*rng), (*noise)(*rng));
    return T;
  }
  void AddMeasuredEdge(int from, int to, std::mt19937_64* rng,
                       std::normal_distribution<double>* noise, bool loop) {
    graph_->AddEdge({.from = from,
                     .to = to,
                     .T_from_to = Truth(from).inverse() * Truth(to) * Noisy(rng, noise, 1.0),
                     .information = Matrix6d::Identity() * (loop ? 1e5 : 1e4),
                     .robust = loop,
                     .dead_reckoned = !loop});
  }
  PoseGraph* graph_;
};

class PoseGraphSpillTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("uwscan_pose_graph_test_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

// Two graphs fed the same measurements, one moving those older than its last 100 nodes to disk:
// their window solves, whole solve and information agree to the bit, and the spilling one's
// memory grows by its nodes' poses alone.
TEST_F(PoseGraphSpillTest, RetiredMeasurementsComeBackWithTheSameBitsAndLeaveMemoryFlat) {
  constexpr int kNodes = 3000, kWindow = 100;
  PoseGraph in_memory, spilling(dir_);
  GrowingGraph grow_in_memory(&in_memory), grow_spilling(&spilling);
  std::int64_t memory_half = 0, spilling_memory_half = 0;
  for (int i = 0; i < kNodes; ++i) {
    grow_in_memory.AddNode(i);
    grow_spilling.AddNode(i);
    spilling.RetireBefore(i + 1 - kWindow);
    if (i % 50 == 49) {
      const PoseGraphSolve a = in_memory.SolveWindow(i + 1 - 40, {});
      const PoseGraphSolve b = spilling.SolveWindow(i + 1 - 40, {});
      ASSERT_EQ(a.measurements, b.measurements) << "node " << i;
      for (int node = i + 1 - 40; node <= i; ++node)
        ExpectSameBits(in_memory.pose(node), spilling.pose(node), node);
    }
    if (i + 1 == kNodes / 2) {
      memory_half = in_memory.memory_bytes();
      spilling_memory_half = spilling.memory_bytes();
    }
  }
  EXPECT_THROW(spilling.SolveWindow(1, {}), Error);
  const PoseGraphSolve whole = spilling.Solve({});
  EXPECT_TRUE(whole.converged);
  EXPECT_EQ(whole.measurements, in_memory.Solve({}).measurements);
  for (int node = 0; node < kNodes; ++node)
    ExpectSameBits(in_memory.pose(node), spilling.pose(node), node);
  EXPECT_EQ(in_memory.calibration().scale_error, spilling.calibration().scale_error);
  const std::optional<Eigen::SparseMatrix<double>> a = in_memory.Information();
  const std::optional<Eigen::SparseMatrix<double>> b = spilling.Information();
  ASSERT_TRUE(a && b);
  EXPECT_EQ(Eigen::SparseMatrix<double>(*a - *b).norm(), 0.0);

  // Per node from the middle of the dive to its end: a few hundred bytes of measurements held,
  // against the nodes' poses alone (56 bytes, at most twice that as a vector doubles).
  const double per_node =
      static_cast<double>(in_memory.memory_bytes() - memory_half) / (kNodes / 2);
  const double spilling_per_node =
      static_cast<double>(spilling.memory_bytes() - spilling_memory_half) / (kNodes / 2);
  EXPECT_GT(per_node, 300.0);
  EXPECT_LE(spilling_per_node, 2.0 * 56.0);
}

// A copy made while the graph spills (its old measurements read back) solves to the bits the
// graph itself solves to at that moment, on another thread while the graph grows, and the copy
// sees nothing the graph gets after it was made.
TEST_F(PoseGraphSpillTest, AnInMemoryCopySolvesToTheBitsOfTheGraphOnAnotherThread) {
  constexpr int kNodes = 600, kWindow = 100;
  PoseGraph graph(dir_);
  GrowingGraph grow(&graph);
  for (int i = 0; i < kNodes; ++i) {
    grow.AddNode(i);
    graph.RetireBefore(i + 1 - kWindow);
  }
  PoseGraph copy = graph.InMemoryCopy();
  std::thread solving([&copy] { copy.Solve({}); });
  for (int i = kNodes; i < kNodes + 200; ++i) {
    grow.AddNode(i);
    graph.RetireBefore(i + 1 - kWindow);
    if (i % 50 == 49) graph.SolveWindow(i + 1 - 40, {});
  }
  solving.join();
  ASSERT_EQ(copy.node_count(), kNodes);
  EXPECT_GT(copy.memory_bytes(), graph.memory_bytes());  // every measurement in memory
  PoseGraph same(dir_ / "same");
  std::filesystem::create_directories(dir_ / "same");
  GrowingGraph grow_same(&same);
  for (int i = 0; i < kNodes; ++i) {
    grow_same.AddNode(i);
    same.RetireBefore(i + 1 - kWindow);
  }
  same.Solve({});
  for (int node = 0; node < kNodes; ++node) ExpectSameBits(same.pose(node), copy.pose(node), node);
  EXPECT_EQ(same.calibration().scale_error, copy.calibration().scale_error);
  EXPECT_EQ(same.calibration().misalignment_rad, copy.calibration().misalignment_rad);
  // The graph takes the copy's calibration; one that estimates none refuses it.
  graph.set_calibration(copy.calibration());
  EXPECT_EQ(graph.calibration().scale_error, copy.calibration().scale_error);
  PoseGraph plain;
  EXPECT_THROW(plain.set_calibration({}), Error);
}

// The spill is a SpillFile (spill_file_test: nameless, gone with its owner or its process).
TEST_F(PoseGraphSpillTest, TheSpillFileIsNeverNamedInItsFolder) {
  PoseGraph graph(dir_);
  GrowingGraph grow(&graph);
  for (int i = 0; i < 600; ++i) {
    grow.AddNode(i);
    graph.RetireBefore(i + 1 - 50);
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir_));
  EXPECT_NO_THROW(graph.Solve({.max_iterations = 1}));
}

TEST_F(PoseGraphSpillTest, AGraphWithoutASpillFolderKeepsEverything) {
  PoseGraph graph;
  GrowingGraph grow(&graph);
  for (int i = 0; i < 600; ++i) {
    grow.AddNode(i);
    graph.RetireBefore(i + 1 - 50);
  }
  EXPECT_NO_THROW(graph.SolveWindow(1, {.max_iterations = 1}));
}

TEST_F(PoseGraphSpillTest, AFolderThatCannotHoldTheSpillIsNamed) {
  PoseGraph graph(dir_ / "missing");
  GrowingGraph grow(&graph);
  try {
    for (int i = 0; i < 600; ++i) {
      grow.AddNode(i);
      graph.RetireBefore(i + 1 - 50);
    }
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace uwscan::mapping::test
