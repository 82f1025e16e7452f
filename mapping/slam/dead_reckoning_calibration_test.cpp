#include "mapping/slam/dead_reckoning_calibration.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "mapping/slam/pose_graph.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping::test {
namespace {

Eigen::Isometry3d Pose(double x, double y, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, 9.0);
  return T;
}

// A dead-reckoned motion as a DVL with this calibration reports the true one T_a_b.
Eigen::Isometry3d DeadReckoned(const Eigen::Isometry3d& T_a_b, double scale_error,
                               double misalignment) {
  Eigen::Isometry3d out = T_a_b;
  const Eigen::Vector3d t = T_a_b.translation();
  const Eigen::Vector2d turned = Eigen::Rotation2Dd(misalignment) * t.head<2>();
  out.translation() << (1.0 + scale_error) * turned, t.z();
  return out;
}

TEST(DeadReckoningCalibration, CorrectUndoesTheScaleAndTheMisalignment) {
  const Eigen::Isometry3d truth = Pose(0.4, -0.2, 0.3);
  const DeadReckoningCalibration calibration{0.02, -0.015};
  const Eigen::Isometry3d corrected = calibration.CorrectMotion(
      DeadReckoned(truth, calibration.scale_error, calibration.misalignment_rad));
  EXPECT_LT((corrected.translation() - truth.translation()).norm(), 1e-12);
  EXPECT_LT((corrected.linear() - truth.linear()).norm(), 1e-12);
}

// An L-shaped survey: dead-reckoned edges all along, and exact scan-matched motions only on a few
// legs. The graph must find the DVL's scale error and misalignment from those few, and then
// place every node, also where only the dead reckoning saw the motion.
TEST(PoseGraph, EstimatesTheDeadReckoningsScaleErrorAndMisalignment) {
  const double scale_error = -0.015, misalignment = 0.012;
  std::vector<Eigen::Isometry3d> truth;
  for (int i = 0; i <= 20; ++i) truth.push_back(Pose(0.25 * i, 0.0, 0.0));
  for (int i = 1; i <= 20; ++i) truth.push_back(Pose(5.0, 0.25 * i, M_PI / 2.0));
  PoseGraph graph;
  graph.EstimateDeadReckoningCalibration(0.01, 0.01);
  Matrix6d odometry = Matrix6d::Zero();
  odometry(2, 2) = 1e8;                                       // heading, 0.1 mrad
  odometry(3, 3) = odometry(4, 4) = 1.0 / (0.0005 * 0.0005);  // x, y: 0.5 mm
  Eigen::Isometry3d believed = truth[0];
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (i > 0) {
      const Eigen::Isometry3d dead_reckoned =
          DeadReckoned(truth[i - 1].inverse() * truth[i], scale_error, misalignment);
      believed = believed * dead_reckoned;
    }
    graph.AddNode(believed);
    graph.AddDepth({static_cast<int>(i), 9.0, 0.001});
    graph.AddGravity({static_cast<int>(i), Eigen::Vector3d::UnitZ(), 0.0005});
    if (i == 0) continue;
    const int from = static_cast<int>(i) - 1, to = static_cast<int>(i);
    graph.AddEdge({from, to,
                   DeadReckoned(truth[i - 1].inverse() * truth[i], scale_error, misalignment),
                   odometry, false, 3.0, true});
    if (i % 5 == 0) {  // a scan match now and then
      graph.AddEdge(
          {from, to, truth[i - 1].inverse() * truth[i], Matrix6d::Identity() * 1e8, false, 3.0});
    }
  }
  Matrix6d start = Matrix6d::Identity() * 1e10;
  graph.AddPrior({0, truth[0], start});
  ASSERT_TRUE(graph.Solve({}).converged);
  // Within 2 % of their values: the zero-mean prior shrinks them a little.
  EXPECT_NEAR(graph.calibration().scale_error, scale_error, 3e-4);
  EXPECT_NEAR(graph.calibration().misalignment_rad, misalignment, 2.4e-4);
  for (std::size_t i = 0; i < truth.size(); ++i) {
    EXPECT_LT((graph.pose(static_cast<int>(i)).translation() - truth[i].translation()).norm(), 1e-3)
        << "node " << i;
  }
}

TEST(PoseGraph, ADeadReckonedEdgeNeedsTheCalibrationFirst) {
  PoseGraph graph;
  graph.AddNode(Pose(0, 0, 0));
  graph.AddNode(Pose(1, 0, 0));
  EXPECT_THROW(graph.AddEdge({0, 1, Pose(1, 0, 0), Matrix6d::Identity(), false, 3.0, true}), Error);
  EXPECT_THROW(graph.EstimateDeadReckoningCalibration(0.0, 0.01), Error);
  graph.EstimateDeadReckoningCalibration(0.01, 0.01);
  EXPECT_THROW(graph.EstimateDeadReckoningCalibration(0.01, 0.01), Error);
}

}  // namespace
}  // namespace uwscan::mapping::test
