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
#include <cstdint>
#include <string>

#include "mapping/slam/graph_measurements.hpp"
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
  // Each node's estimate: its quaternion (x, y, z, w as Eigen stores it) and its position, the
  // parameter blocks of the problem each solve builds (no node is added while one runs).
  struct Node {
    std::array<double, 4> q;
    std::array<double, 3> p;
  };
  std::vector<Node> nodes;
  // The dead reckoning's [scale error, misalignment] and its zero-mean prior, once estimated.
  std::unique_ptr<std::array<double, 2>> calibration;
  CalibrationPriorCost calibration_prior{};
  // The measurements in memory, and those moved to the spill file (RetireBefore), which come
  // before them.
  GraphMeasurements measurements;
  std::unique_ptr<MeasurementSpill> spill;
  std::filesystem::path spill_folder;
  int retired_before = 0;  // every measurement spilled touches only nodes before this one
  ceres::EigenQuaternionManifold quaternion_manifold;  // shared by every problem built

  void RequireNode(int node, const std::string& what) const {
    if (node < 0 || node >= static_cast<int>(nodes.size())) {
      throw Error("pose graph: " + what + ": no node " + std::to_string(node));
    }
  }
  double* q(int node) { return nodes[static_cast<size_t>(node)].q.data(); }
  double* p(int node) { return nodes[static_cast<size_t>(node)].p.data(); }

  // Adds measurement `i` of `from` to `problem`, which owns the cost and loss made for it.
  void AddTo(const GraphMeasurements& from, std::size_t i, ceres::Problem* problem) {
    const GraphMeasurements::Entry& entry = from.entries[i];
    const auto at = static_cast<size_t>(entry.index);
    switch (entry.kind) {
      case GraphMeasurements::Kind::kEdge: {
        const GraphMeasurements::Edge& e = from.edges[at];
        const RelativePoseMeasurement measurement{e.q_from_to, e.t_from_to, e.sqrt_information};
        ceres::LossFunction* loss = e.robust ? new ceres::HuberLoss(e.huber_scale) : nullptr;
        if (e.dead_reckoned) {
          problem->AddResidualBlock(new DeadReckonedPoseCost(measurement), loss, q(e.from),
                                    p(e.from), q(e.to), p(e.to), calibration->data());
        } else {
          problem->AddResidualBlock(new RelativePoseCost(measurement), loss, q(e.from), p(e.from),
                                    q(e.to), p(e.to));
        }
        return;
      }
      case GraphMeasurements::Kind::kDepth: {
        const DepthPrior& d = from.depths[at];
        problem->AddResidualBlock(
            new ceres::AutoDiffCostFunction<DepthCost, 1, 3>(new DepthCost{d.z_m, d.sigma_m}),
            nullptr, p(d.node));
        return;
      }
      case GraphMeasurements::Kind::kGravity: {
        const GravityPrior& g = from.gravities[at];
        problem->AddResidualBlock(new ceres::AutoDiffCostFunction<GravityCost, 3, 4>(
                                      new GravityCost{g.down_in_V, g.sigma_rad}),
                                  nullptr, q(g.node));
        return;
      }
      case GraphMeasurements::Kind::kPrior: {
        const GraphMeasurements::Prior& r = from.priors[at];
        problem->AddResidualBlock(new ceres::AutoDiffCostFunction<PriorCost, 6, 4, 3>(
                                      new PriorCost{r.q_W_V, r.t_W_V, r.sqrt_information}),
                                  nullptr, q(r.node), p(r.node));
        return;
      }
    }
  }

  // Every measurement in one problem: the calibration and its prior first (a mapper estimates it
  // before its first node), then each node's rotation and position, then the measurements in the
  // order they were added, the spilled ones read back first.
  std::unique_ptr<ceres::Problem> WholeProblem() {
    ceres::Problem::Options options;
    options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    auto problem = std::make_unique<ceres::Problem>(options);
    if (calibration) {
      problem->AddParameterBlock(calibration->data(), 2);
      problem->AddResidualBlock(new ceres::AutoDiffCostFunction<CalibrationPriorCost, 2, 2>(
                                    new CalibrationPriorCost(calibration_prior)),
                                nullptr, calibration->data());
    }
    for (int node = 0; node < static_cast<int>(nodes.size()); ++node) {
      problem->AddParameterBlock(q(node), 4, &quaternion_manifold);
      problem->AddParameterBlock(p(node), 3);
    }
    if (spill) {
      const GraphMeasurements spilled = spill->ReadAll();
      for (std::size_t i = 0; i < spilled.size(); ++i) AddTo(spilled, i, problem.get());
    }
    for (std::size_t i = 0; i < measurements.size(); ++i) AddTo(measurements, i, problem.get());
    return problem;
  }

  // The information J^T J at the current estimate, J the whitened residuals' Jacobian (robust
  // losses applied) in the tangent spaces, columns ordered [q_0, p_0, q_1, p_1, ...,
  // calibration]: node i at 6 i, its rotation (Ceres's quaternion tangent) then its position.
  // std::nullopt when a residual cannot be evaluated there.
  std::optional<Eigen::SparseMatrix<double>> Information() {
    const std::unique_ptr<ceres::Problem> problem = WholeProblem();
    ceres::Problem::EvaluateOptions options;
    for (int i = 0; i < static_cast<int>(nodes.size()); ++i) {
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

PoseGraph::PoseGraph(const std::filesystem::path& spill_folder) : impl_(std::make_unique<Impl>()) {
  impl_->spill_folder = spill_folder;
}
PoseGraph::~PoseGraph() = default;
PoseGraph::PoseGraph(PoseGraph&&) noexcept = default;
PoseGraph& PoseGraph::operator=(PoseGraph&&) noexcept = default;

int PoseGraph::AddNode(const Eigen::Isometry3d& T_W_V) {
  RequireRigid(T_W_V, "AddNode");
  impl_->nodes.emplace_back();
  const int node = node_count() - 1;
  set_pose(node, T_W_V);
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
  m.measurements.Add(
      GraphMeasurements::Edge{.from = edge.from,
                              .to = edge.to,
                              .q_from_to = Eigen::Quaterniond(edge.T_from_to.linear()),
                              .t_from_to = edge.T_from_to.translation(),
                              .sqrt_information = SqrtPsd(edge.information),
                              .robust = edge.robust,
                              .dead_reckoned = edge.dead_reckoned,
                              .huber_scale = edge.huber_scale});
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
  m.calibration_prior = {scale_sigma, misalignment_sigma_rad};
}

bool PoseGraph::estimates_calibration() const { return impl_->calibration != nullptr; }

DeadReckoningCalibration PoseGraph::calibration() const {
  if (!impl_->calibration) return {};
  return {(*impl_->calibration)[0], (*impl_->calibration)[1]};
}

void PoseGraph::set_calibration(const DeadReckoningCalibration& calibration) {
  if (!impl_->calibration)
    throw Error("pose graph: set_calibration: the calibration is not estimated");
  if (!std::isfinite(calibration.scale_error) || !std::isfinite(calibration.misalignment_rad))
    throw Error("pose graph: set_calibration: expected finite values");
  *impl_->calibration = {calibration.scale_error, calibration.misalignment_rad};
}

void PoseGraph::AddDepth(const DepthPrior& prior) {
  Impl& m = *impl_;
  m.RequireNode(prior.node, "AddDepth");
  if (!std::isfinite(prior.z_m) || !(prior.sigma_m > 0.0)) {
    throw Error("pose graph: AddDepth: expected a finite depth and sigma_m > 0");
  }
  m.measurements.Add(prior);
}

void PoseGraph::AddGravity(const GravityPrior& prior) {
  Impl& m = *impl_;
  m.RequireNode(prior.node, "AddGravity");
  if (!prior.down_in_V.allFinite() || std::abs(prior.down_in_V.norm() - 1.0) > 1e-6 ||
      !(prior.sigma_rad > 0.0)) {
    throw Error("pose graph: AddGravity: expected a unit down vector and sigma_rad > 0");
  }
  m.measurements.Add(prior);
}

void PoseGraph::AddPrior(const PosePrior& prior) {
  Impl& m = *impl_;
  m.RequireNode(prior.node, "AddPrior");
  RequireRigid(prior.T_W_V, "AddPrior");
  RequireInformation(prior.information, "AddPrior");
  m.measurements.Add(GraphMeasurements::Prior{.node = prior.node,
                                              .q_W_V = Eigen::Quaterniond(prior.T_W_V.linear()),
                                              .t_W_V = prior.T_W_V.translation(),
                                              .sqrt_information = SqrtPsd(prior.information)});
}

void PoseGraph::RetireBefore(int first_node) {
  Impl& m = *impl_;
  if (m.spill_folder.empty() || first_node <= m.retired_before) return;
  const std::size_t older = m.measurements.OlderThan(first_node);
  if (older < kRetireAtOnce) return;
  if (!m.spill) m.spill = std::make_unique<MeasurementSpill>(m.spill_folder);
  m.spill->Append(m.measurements, older);
  m.measurements.DropFirst(older);
  m.retired_before = first_node;
}

PoseGraph PoseGraph::InMemoryCopy() const {
  const Impl& m = *impl_;
  PoseGraph copy;
  Impl& c = *copy.impl_;
  c.nodes = m.nodes;
  if (m.calibration) c.calibration = std::make_unique<std::array<double, 2>>(*m.calibration);
  c.calibration_prior = m.calibration_prior;
  if (m.spill) c.measurements = m.spill->ReadAll();
  c.measurements.AddAll(m.measurements);
  return copy;
}

std::int64_t PoseGraph::memory_bytes() const {
  return static_cast<std::int64_t>(impl_->nodes.capacity() * sizeof(Impl::Node)) +
         impl_->measurements.memory_bytes();
}

int PoseGraph::node_count() const { return static_cast<int>(impl_->nodes.size()); }

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
  options.Check();
  const std::unique_ptr<ceres::Problem> problem = impl_->WholeProblem();
  return SolveProblem(problem.get(), options);
}

PoseGraphSolve PoseGraph::SolveWindow(int first_free_node, const PoseGraphOptions& options) {
  options.Check();
  Impl& m = *impl_;
  if (first_free_node < 0 || first_free_node >= node_count()) {
    throw Error("pose graph: SolveWindow: first free node " + std::to_string(first_free_node) +
                " outside [0, " + std::to_string(node_count()) + ")");
  }
  if (first_free_node < m.retired_before) {
    throw Error("pose graph: SolveWindow: first free node " + std::to_string(first_free_node) +
                " is before node " + std::to_string(m.retired_before) +
                ", whose measurements were moved out of memory (RetireBefore)");
  }
  ceres::Problem::Options options_shared_manifold;
  options_shared_manifold.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem window(options_shared_manifold);
  std::vector<int> nodes;
  for (const std::size_t i : m.measurements.From(first_free_node)) {
    m.AddTo(m.measurements, i, &window);
    for (const int node : m.measurements.NodesOf(i))
      if (node >= 0) nodes.push_back(node);
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
