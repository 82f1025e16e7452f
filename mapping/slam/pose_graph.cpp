#include "mapping/slam/pose_graph.hpp"

#include <ceres/autodiff_cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "mapping/slam/inverse_blocks.hpp"
#include "mapping/slam/relative_pose_cost.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/common/symmetrized.hpp"

namespace uwscan::mapping {
namespace {

// The calibration's zero-mean prior.
struct CalibrationPriorCost {
  double scale_sigma, misalignment_sigma_rad;
  template <typename T>
  bool operator()(const T* c, T* residual) const {
    residual[0] = c[0] / T(scale_sigma);
    residual[1] = c[1] / T(misalignment_sigma_rad);
    return true;
  }
};

struct PriorCost {
  Eigen::Quaterniond q_meas;
  Eigen::Vector3d t_meas;
  Matrix6d sqrt_information;

  template <typename T>
  bool operator()(const T* q_raw, const T* p_raw, T* residual_raw) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_raw);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p(p_raw);
    // Rotation error as for the edges; the position error is the position's own (not about
    // the world origin, which would tie it to the rotation through the vehicle's distance).
    Eigen::Quaternion<T> q_delta = Eigen::Quaternion<T>(q) * q_meas.conjugate().cast<T>();
    if (q_delta.w() < T(0)) q_delta.coeffs() = -q_delta.coeffs();
    Eigen::Matrix<T, 6, 1> e;
    e << T(2) * q_delta.vec(), p - t_meas.cast<T>();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> residual(residual_raw);
    residual = sqrt_information.cast<T>() * e;
    return true;
  }
};

struct DepthCost {
  double z_m, sigma_m;
  template <typename T>
  bool operator()(const T* p, T* residual) const {
    residual[0] = (p[2] - T(z_m)) / T(sigma_m);
    return true;
  }
};

struct GravityCost {
  Eigen::Vector3d down_in_V;
  double sigma_rad;
  template <typename T>
  bool operator()(const T* q_raw, T* residual_raw) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q(q_raw);
    const Eigen::Matrix<T, 3, 1> down = q.conjugate() * Eigen::Matrix<T, 3, 1>(T(0), T(0), T(1));
    Eigen::Map<Eigen::Matrix<T, 3, 1>> residual(residual_raw);
    residual = (down - down_in_V.cast<T>()) / T(sigma_rad);
    return true;
  }
};

void RequireInformation(const Matrix6d& information, const std::string& what) {
  if (!information.allFinite() || !information.isApprox(information.transpose(), 1e-9)) {
    throw Error("pose graph: " + what + ": information must be finite and symmetric");
  }
}

void RequireRigid(const Eigen::Isometry3d& T, const std::string& what) {
  const Eigen::Matrix3d R = T.linear();
  if (!T.matrix().allFinite() || (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-6) {
    throw Error("pose graph: " + what + ": expected a finite rigid transform");
  }
}

}  // namespace

void PoseGraphOptions::Check() const {
  const OptionChecks check("PoseGraphOptions");
  check.GreaterThan("max_iterations", max_iterations, 0);
  check.GreaterThan("threads", threads, 0);
  check.InRange("function_tolerance", function_tolerance, 0.0, 1.0, Interval::kOpen);
}

Vector6d PoseError(const Eigen::Isometry3d& T_a, const Eigen::Isometry3d& T_b) {
  const Eigen::Matrix3d R = T_a.linear() * T_b.linear().transpose();
  const Eigen::AngleAxisd rotation(R);
  Vector6d e;
  e << rotation.angle() * rotation.axis(), T_a.translation() - R * T_b.translation();
  return e;
}

Matrix6d SqrtPsd(const Matrix6d& information) {
  const Eigen::SelfAdjointEigenSolver<Matrix6d> solver(Symmetrized(information));
  const Vector6d root = solver.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return solver.eigenvectors() * root.asDiagonal() * solver.eigenvectors().transpose();
}

struct PoseGraph::Impl {
  // Parameter blocks: one quaternion (x, y, z, w as Eigen stores it) and one position per node,
  // each in its own allocation so their addresses never move.
  std::vector<std::unique_ptr<std::array<double, 4>>> rotations;
  std::vector<std::unique_ptr<std::array<double, 3>>> positions;
  std::unique_ptr<ceres::Problem> problem;
  // The dead reckoning's [scale error, misalignment], a parameter block once estimated.
  std::unique_ptr<std::array<double, 2>> calibration;
  // Every measurement as the problem holds it (the problem owns its cost and loss), and those of
  // each node, so that a window's problem can be built from them alone (SolveWindow).
  struct Measurement {
    ceres::CostFunction* cost = nullptr;
    ceres::LossFunction* loss = nullptr;
    std::vector<double*> blocks;
    std::vector<int> nodes;
  };
  std::vector<Measurement> measurements;
  std::vector<std::vector<int>> measurements_of_node;
  ceres::EigenQuaternionManifold quaternion_manifold;  // shared by the windows' problems

  Impl() {
    ceres::Problem::Options options;
    options.manifold_ownership = ceres::TAKE_OWNERSHIP;
    problem = std::make_unique<ceres::Problem>(options);
  }

  void RequireNode(int node, const std::string& what) const {
    if (node < 0 || node >= static_cast<int>(rotations.size())) {
      throw Error("pose graph: " + what + ": no node " + std::to_string(node));
    }
  }
  double* q(int node) { return rotations[static_cast<size_t>(node)]->data(); }
  double* p(int node) { return positions[static_cast<size_t>(node)]->data(); }

  // Adds a measurement of the given nodes (their rotation and position blocks in that order,
  // then `extra`, the calibration, when given) to the problem and to the record.
  void AddMeasurement(ceres::CostFunction* cost, ceres::LossFunction* loss,
                      const std::vector<int>& nodes, bool with_rotation, bool with_position,
                      double* extra = nullptr) {
    Measurement m{cost, loss, {}, nodes};
    for (const int node : nodes) {
      if (with_rotation) m.blocks.push_back(q(node));
      if (with_position) m.blocks.push_back(p(node));
    }
    if (extra) m.blocks.push_back(extra);
    problem->AddResidualBlock(cost, loss, m.blocks);
    const int index = static_cast<int>(measurements.size());
    for (const int node : nodes) measurements_of_node[static_cast<size_t>(node)].push_back(index);
    measurements.push_back(std::move(m));
  }

  // The measurements that touch a node from first_node on, each once, in the order added.
  std::vector<int> MeasurementsFrom(int first_node) const {
    std::vector<int> indices;
    for (size_t node = static_cast<size_t>(first_node); node < measurements_of_node.size(); ++node)
      indices.insert(indices.end(), measurements_of_node[node].begin(),
                     measurements_of_node[node].end());
    std::sort(indices.begin(), indices.end());
    indices.erase(std::unique(indices.begin(), indices.end()), indices.end());
    return indices;
  }

  // The information J^T J at the current estimate, J the whitened residuals' Jacobian (robust
  // losses applied) in the tangent spaces, columns ordered [q_0, p_0, q_1, p_1, ...,
  // calibration]: node i at 6 i, its rotation (Ceres's quaternion tangent) then its position.
  // std::nullopt when a residual cannot be evaluated there.
  std::optional<Eigen::SparseMatrix<double>> Information() {
    ceres::Problem::EvaluateOptions options;
    for (int i = 0; i < static_cast<int>(rotations.size()); ++i) {
      options.parameter_blocks.push_back(q(i));
      options.parameter_blocks.push_back(p(i));
    }
    if (calibration) options.parameter_blocks.push_back(calibration->data());
    options.num_threads = 1;
    ceres::CRSMatrix crs;
    double cost = 0.0;
    if (!problem->Evaluate(options, &cost, nullptr, nullptr, &crs)) return std::nullopt;
    const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::RowMajor>> jacobian(
        crs.num_rows, crs.num_cols, static_cast<Eigen::Index>(crs.values.size()), crs.rows.data(),
        crs.cols.data(), crs.values.data());
    const Eigen::SparseMatrix<double> J = jacobian;
    return Eigen::SparseMatrix<double>(J.transpose()) * J;
  }
};

PoseGraph::PoseGraph() : impl_(std::make_unique<Impl>()) {}
PoseGraph::~PoseGraph() = default;
PoseGraph::PoseGraph(PoseGraph&&) noexcept = default;
PoseGraph& PoseGraph::operator=(PoseGraph&&) noexcept = default;

int PoseGraph::AddNode(const Eigen::Isometry3d& T_W_V) {
  RequireRigid(T_W_V, "AddNode");
  Impl& m = *impl_;
  m.rotations.push_back(std::make_unique<std::array<double, 4>>());
  m.positions.push_back(std::make_unique<std::array<double, 3>>());
  const int node = static_cast<int>(m.rotations.size()) - 1;
  set_pose(node, T_W_V);
  m.problem->AddParameterBlock(m.q(node), 4, new ceres::EigenQuaternionManifold);
  m.problem->AddParameterBlock(m.p(node), 3);
  m.measurements_of_node.emplace_back();
  return node;
}

void PoseGraph::AddEdge(const RelativePoseEdge& edge) {
  Impl& m = *impl_;
  m.RequireNode(edge.from, "AddEdge");
  m.RequireNode(edge.to, "AddEdge");
  RequireRigid(edge.T_from_to, "AddEdge");
  RequireInformation(edge.information, "AddEdge");
  if (edge.robust && !(edge.huber_scale > 0.0))
    throw Error("pose graph: AddEdge: huber_scale must be > 0");
  if (edge.dead_reckoned && !m.calibration) {
    throw Error(
        "pose graph: AddEdge: a dead-reckoned edge needs EstimateDeadReckoningCalibration first");
  }
  // The problem owns each loss (one per edge: Ceres deletes them one by one).
  ceres::LossFunction* loss = edge.robust ? new ceres::HuberLoss(edge.huber_scale) : nullptr;
  const RelativePoseMeasurement measurement{Eigen::Quaterniond(edge.T_from_to.linear()),
                                            edge.T_from_to.translation(),
                                            SqrtPsd(edge.information)};
  if (edge.dead_reckoned) {
    auto* cost = new DeadReckonedPoseCost(measurement);
    m.AddMeasurement(cost, loss, {edge.from, edge.to}, true, true, m.calibration->data());
    return;
  }
  auto* cost = new RelativePoseCost(measurement);
  m.AddMeasurement(cost, loss, {edge.from, edge.to}, true, true);
}

void PoseGraph::EstimateDeadReckoningCalibration(double scale_sigma,
                                                 double misalignment_sigma_rad) {
  Impl& m = *impl_;
  if (m.calibration) throw Error("pose graph: EstimateDeadReckoningCalibration: called twice");
  if (!(scale_sigma > 0.0 && std::isfinite(scale_sigma)) ||
      !(misalignment_sigma_rad > 0.0 && std::isfinite(misalignment_sigma_rad))) {
    throw Error("pose graph: EstimateDeadReckoningCalibration: expected finite sigmas > 0");
  }
  m.calibration = std::make_unique<std::array<double, 2>>(std::array<double, 2>{0.0, 0.0});
  m.problem->AddParameterBlock(m.calibration->data(), 2);
  m.AddMeasurement(new ceres::AutoDiffCostFunction<CalibrationPriorCost, 2, 2>(
                       new CalibrationPriorCost{scale_sigma, misalignment_sigma_rad}),
                   nullptr, {}, false, false, m.calibration->data());
}

bool PoseGraph::estimates_calibration() const { return impl_->calibration != nullptr; }

DeadReckoningCalibration PoseGraph::calibration() const {
  if (!impl_->calibration) return {};
  return {(*impl_->calibration)[0], (*impl_->calibration)[1]};
}

void PoseGraph::AddDepth(const DepthPrior& prior) {
  Impl& m = *impl_;
  m.RequireNode(prior.node, "AddDepth");
  if (!std::isfinite(prior.z_m) || !(prior.sigma_m > 0.0)) {
    throw Error("pose graph: AddDepth: expected a finite depth and sigma_m > 0");
  }
  m.AddMeasurement(
      new ceres::AutoDiffCostFunction<DepthCost, 1, 3>(new DepthCost{prior.z_m, prior.sigma_m}),
      nullptr, {prior.node}, false, true);
}

void PoseGraph::AddGravity(const GravityPrior& prior) {
  Impl& m = *impl_;
  m.RequireNode(prior.node, "AddGravity");
  if (!prior.down_in_V.allFinite() || std::abs(prior.down_in_V.norm() - 1.0) > 1e-6 ||
      !(prior.sigma_rad > 0.0)) {
    throw Error("pose graph: AddGravity: expected a unit down vector and sigma_rad > 0");
  }
  m.AddMeasurement(new ceres::AutoDiffCostFunction<GravityCost, 3, 4>(
                       new GravityCost{prior.down_in_V, prior.sigma_rad}),
                   nullptr, {prior.node}, true, false);
}

void PoseGraph::AddPrior(const PosePrior& prior) {
  Impl& m = *impl_;
  m.RequireNode(prior.node, "AddPrior");
  RequireRigid(prior.T_W_V, "AddPrior");
  RequireInformation(prior.information, "AddPrior");
  m.AddMeasurement(new ceres::AutoDiffCostFunction<PriorCost, 6, 4, 3>(
                       new PriorCost{Eigen::Quaterniond(prior.T_W_V.linear()),
                                     prior.T_W_V.translation(), SqrtPsd(prior.information)}),
                   nullptr, {prior.node}, true, true);
}

int PoseGraph::node_count() const { return static_cast<int>(impl_->rotations.size()); }

Eigen::Isometry3d PoseGraph::pose(int node) const {
  impl_->RequireNode(node, "pose");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(impl_->q(node)).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(impl_->p(node));
  return T;
}

void PoseGraph::set_pose(int node, const Eigen::Isometry3d& T_W_V) {
  impl_->RequireNode(node, "set_pose");
  RequireRigid(T_W_V, "set_pose");
  Eigen::Map<Eigen::Quaterniond>(impl_->q(node)) = Eigen::Quaterniond(T_W_V.linear()).normalized();
  Eigen::Map<Eigen::Vector3d>(impl_->p(node)) = T_W_V.translation();
}

namespace {

PoseGraphSolve SolveProblem(ceres::Problem* problem, const PoseGraphOptions& options) {
  options.Check();
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = options.threads;
  solver.function_tolerance = options.function_tolerance;
  solver.gradient_tolerance = 1e-12;
  solver.parameter_tolerance = 1e-10;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, problem, &summary);
  PoseGraphSolve result;
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.iterations = static_cast<int>(summary.iterations.size());
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.measurements = problem->NumResidualBlocks();
  return result;
}

}  // namespace

PoseGraphSolve PoseGraph::Solve(const PoseGraphOptions& options) {
  return SolveProblem(impl_->problem.get(), options);
}

PoseGraphSolve PoseGraph::SolveWindow(int first_free_node, const PoseGraphOptions& options) {
  options.Check();
  Impl& m = *impl_;
  if (first_free_node < 0 || first_free_node >= node_count()) {
    throw Error("pose graph: SolveWindow: first free node " + std::to_string(first_free_node) +
                " outside [0, " + std::to_string(node_count()) + ")");
  }
  // The window's problem borrows the costs, losses and manifold: the whole graph's problem and
  // Impl own them.
  ceres::Problem::Options borrowed;
  borrowed.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  borrowed.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  borrowed.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem window(borrowed);
  std::vector<int> nodes;
  for (const int index : m.MeasurementsFrom(first_free_node)) {
    const Impl::Measurement& measurement = m.measurements[static_cast<size_t>(index)];
    window.AddResidualBlock(measurement.cost, measurement.loss, measurement.blocks);
    nodes.insert(nodes.end(), measurement.nodes.begin(), measurement.nodes.end());
  }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  for (const int node : nodes) {
    const bool held = node < first_free_node;
    for (double* block : {m.q(node), m.p(node)}) {
      if (!window.HasParameterBlock(block)) continue;
      if (block == m.q(node)) window.SetManifold(block, &m.quaternion_manifold);
      if (held) window.SetParameterBlockConstant(block);
    }
  }
  if (m.calibration && window.HasParameterBlock(m.calibration->data()))
    window.SetParameterBlockConstant(m.calibration->data());
  return SolveProblem(&window, options);
}

std::optional<std::vector<Matrix6d>> PoseGraph::Covariances() const {
  std::vector<int> nodes(static_cast<size_t>(node_count()));
  for (int i = 0; i < node_count(); ++i) nodes[static_cast<size_t>(i)] = i;
  return Covariances(nodes);
}

std::optional<std::vector<Matrix6d>> PoseGraph::Covariances(const std::vector<int>& nodes) const {
  for (const int node : nodes) impl_->RequireNode(node, "Covariances");
  std::vector<IndexRange> blocks;
  for (const int i : nodes) blocks.push_back({6 * i, 6});
  const std::optional<Eigen::SparseMatrix<double>> information = impl_->Information();
  if (!information) return std::nullopt;
  const std::optional<std::vector<Eigen::MatrixXd>> tangent = InverseBlocks(*information, blocks);
  if (!tangent) return std::nullopt;
  // Ceres's quaternion tangent is half the rotation vector (Plus = [cos|d|, sin|d| d/|d|] * q):
  // scale to radians of rotation.
  Vector6d to_radians;
  to_radians << 2.0, 2.0, 2.0, 1.0, 1.0, 1.0;
  std::vector<Matrix6d> out;
  out.reserve(nodes.size());
  for (const Eigen::MatrixXd& c : *tangent)
    out.push_back(to_radians.asDiagonal() * c * to_radians.asDiagonal());
  return out;
}

std::optional<Eigen::SparseMatrix<double>> PoseGraph::Information() const {
  std::optional<Eigen::SparseMatrix<double>> information = impl_->Information();
  if (!information) return std::nullopt;
  // Ceres's quaternion tangent is half the rotation vector: in radians the information is
  // S^-1 H S^-1 with S = 2 on the rotations' rows and columns.
  const Eigen::Index rotations = 6 * static_cast<Eigen::Index>(node_count());
  const auto scale = [&](Eigen::Index i) { return i < rotations && i % 6 < 3 ? 0.5 : 1.0; };
  for (Eigen::Index column = 0; column < information->outerSize(); ++column) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(*information, column); it; ++it)
      it.valueRef() *= scale(it.row()) * scale(it.col());
  }
  return information;
}

}  // namespace uwscan::mapping
