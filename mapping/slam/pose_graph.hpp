#pragma once

#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "mapping/slam/dead_reckoning_calibration.hpp"

// A pose graph of vehicle poses T_W_V solved with Ceres (SE(3): position + unit quaternion on
// Ceres's quaternion manifold). Ceres stays inside pose_graph.cpp.
namespace uwscan::mapping {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

// A measured motion between two nodes: T_from_to, with its information (inverse covariance)
// for the error e = [w (rad), v (m)] defined by  T_from_to_predicted = exp(e) * T_from_to, a
// left perturbation in the `from` frame about its origin (rotation by w, then translation by v).
// Directions the information leaves at zero are not measured (e.g. depth in an odometry edge,
// which the depth prior holds). `robust`: a Huber loss on the whitened error (scale
// huber_scale, in standard deviations) caps the pull of an outlier (loop closures).
struct RelativePoseEdge {
  int from = 0;
  int to = 0;
  Eigen::Isometry3d T_from_to = Eigen::Isometry3d::Identity();
  Matrix6d information = Matrix6d::Zero();  // symmetric PSD
  bool robust = false;
  double huber_scale = 3.0;  // > 0, used when robust
  // A dead-reckoned motion: its translation is corrected by the graph's estimate of the dead
  // reckoning's calibration before it is compared (EstimateDeadReckoningCalibration first).
  bool dead_reckoned = false;
};

// Absolute measurements of one node from the vehicle's own sensors.
struct DepthPrior {
  int node = 0;
  double z_m = 0.0;      // NED z of {V} in {W}
  double sigma_m = 0.0;  // > 0
};
// Roll and pitch from gravity: the world's down axis seen in {V}, R_W_V^T e_z.
struct GravityPrior {
  int node = 0;
  Eigen::Vector3d down_in_V = Eigen::Vector3d::UnitZ();  // unit
  double sigma_rad = 0.0;                                // > 0
};
// A full pose prior, e.g. the fix the dive starts from. Error [w, p - p_prior]: the rotation
// vector of R R_prior^T and the position error, both along the world's axes.
struct PosePrior {
  int node = 0;
  Eigen::Isometry3d T_W_V = Eigen::Isometry3d::Identity();
  Matrix6d information = Matrix6d::Zero();
};

struct PoseGraphOptions {
  int max_iterations = 50;  // Levenberg-Marquardt iterations, > 0
  int threads = 1;          // Ceres threads, > 0
  // A solve stops once an iteration lowers the cost by less than this fraction, in (0, 1).
  double function_tolerance = 1e-10;
  void Check() const;
};

struct PoseGraphSolve {
  bool converged = false;
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int measurements = 0;  // residual blocks in the problem solved (a window's: those it touches)
};

class PoseGraph {
 public:
  // Measurements retired at once (RetireBefore): writes of about 25 kB, a dozen submaps' worth.
  static constexpr std::size_t kRetireAtOnce = 64;

  // spill_folder: where RetireBefore moves old measurements (empty: they all stay in memory).
  explicit PoseGraph(const std::filesystem::path& spill_folder = {});
  ~PoseGraph();
  PoseGraph(PoseGraph&&) noexcept;
  PoseGraph& operator=(PoseGraph&&) noexcept;

  // Adds a node at its initial estimate; returns its index (0, 1, ...).
  int AddNode(const Eigen::Isometry3d& T_W_V);
  // Throw uwscan::Error on an unknown node, a non-finite value or an unusable information.
  void AddEdge(const RelativePoseEdge& edge);
  void AddDepth(const DepthPrior& prior);
  void AddGravity(const GravityPrior& prior);
  void AddPrior(const PosePrior& prior);
  // Estimates the dead reckoning's speed scale error and misalignment with the poses, from a
  // zero-mean prior with these standard deviations (> 0). Call once, before the first
  // dead-reckoned edge.
  void EstimateDeadReckoningCalibration(double scale_sigma, double misalignment_sigma_rad);
  bool estimates_calibration() const;
  // The current estimate (zero until estimated).
  DeadReckoningCalibration calibration() const;
  // Sets the estimate (e.g. from a solved copy, InMemoryCopy). Throws uwscan::Error when the
  // graph does not estimate it or a value is not finite.
  void set_calibration(const DeadReckoningCalibration& calibration);

  int node_count() const;
  Eigen::Isometry3d pose(int node) const;
  void set_pose(int node, const Eigen::Isometry3d& T_W_V);

  // Solves the whole graph from the current estimates.
  PoseGraphSolve Solve(const PoseGraphOptions& options);
  // Solves only the nodes from first_free_node on, in [0, node_count()): the others and the
  // dead reckoning's calibration stay where they are, and the solve builds and evaluates only
  // the measurements that touch a free node, so it costs what the window holds, whatever the
  // graph's size (a long dive's running solves). SolveWindow(0) differs from Solve only in
  // holding the calibration.
  PoseGraphSolve SolveWindow(int first_free_node, const PoseGraphOptions& options);

  // Memory that does not grow with the graph: the measurements that touch only nodes before
  // first_node, and come before every one that touches a later node, go to a spill file in the
  // spill folder, once at least kRetireAtOnce of them do (nothing without a spill folder). They
  // are read back for Solve, Covariances and Information, with the same bits; SolveWindow from a
  // node before first_node is then refused. The nodes' poses stay in memory (56 bytes each).
  // Throws uwscan::Error when the spill file cannot be created or written.
  void RetireBefore(int first_node);
  // A copy of the graph, its nodes, calibration and every measurement, the spilled ones read back
  // into memory, with no spill folder: its Solve gives the bits this graph's Solve would give now.
  // It shares nothing with this graph, so it can be solved on another thread while this one
  // grows (Mapper's whole solves beside the dive). Throws uwscan::Error when the spill file
  // cannot be read.
  PoseGraph InMemoryCopy() const;
  // The bytes the nodes and the measurements in memory take.
  std::int64_t memory_bytes() const;

  // Marginal covariance of every node at the current estimate, ordered [rotation (rad),
  // position (m)], both in the world frame: T_W_V = exp([w, 0]) applied to the rotation,
  // position + v. From the inverse of the information J^T J (InverseBlocks): the same bits on
  // every run. std::nullopt when the graph leaves a direction unconstrained (rank deficient).
  std::optional<std::vector<Matrix6d>> Covariances() const;
  // The same for the given nodes only, in their order.
  std::optional<std::vector<Matrix6d>> Covariances(const std::vector<int>& nodes) const;
  // The information J^T J at the current estimate (the inverse of the joint covariance, cross
  // terms included): 6 rows and columns per node, node i at 6 i, [rotation (rad), position (m)]
  // as above, then the dead reckoning's calibration when estimated (2). std::nullopt when a
  // measurement cannot be evaluated there.
  std::optional<Eigen::SparseMatrix<double>> Information() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The left-perturbation error e = [w, v] with T_a = exp(e) * T_b (rotation vector of
// R_a R_b^T, and t_a - R_a R_b^T t_b).
Vector6d PoseError(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b);

// Symmetric square root of a PSD matrix (negative eigenvalues from rounding taken as zero).
Matrix6d SqrtPsd(const Matrix6d& information);

}  // namespace uwscan::mapping
