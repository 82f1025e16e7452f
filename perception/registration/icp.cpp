#include "perception/registration/icp.hpp"

#include <omp.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "perception/cloud/nearest_grid.hpp"
#include "perception/registration/rigid_increment.hpp"
#include "perception/registration/svd_alignment.hpp"
#include "perception/registration/target_tree.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::perception {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

constexpr std::ptrdiff_t kBlockSize = 256;  // points per partial sum
constexpr double kEigenvalueFloor = 1e-10;  // relative: smaller eigenvalues of J^T J dropped

int ThreadCount(int threads) { return threads > 0 ? threads : omp_get_max_threads(); }

// -[p]x, so that w x p = MinusSkew(p) w.
Eigen::Matrix3d MinusSkew(const Eigen::Vector3d& p) {
  Eigen::Matrix3d m;
  m << 0.0, p.z(), -p.y(), -p.z(), 0.0, p.x(), p.y(), -p.x(), 0.0;
  return m;
}

// Sums of per-pair terms over fixed blocks of points, added in block order, so the rounding
// does not depend on the thread count.
struct Sums {
  Matrix6d JtJ = Matrix6d::Zero();  // upper triangle until Pass() returns
  Vector6d Jtr = Vector6d::Zero();
  double squared_residual = 0.0;  // sum of r^2 (the method's residual)
  double squared_distance = 0.0;  // sum of |p - q|^2
  std::size_t count = 0;

  void Add(const Sums& other) {
    JtJ += other.JtJ;
    Jtr += other.Jtr;
    squared_residual += other.squared_residual;
    squared_distance += other.squared_distance;
    count += other.count;
  }
};

// Unit normals of the source and target and the least cosine between paired ones, when
// IcpOptions::max_normal_angle_rad gates the pairs.
struct NormalGate {
  const std::vector<Eigen::Vector3f>* source = nullptr;
  const std::vector<Eigen::Vector3f>* target = nullptr;
  float min_cos = -1.0f;
};

// One pass over the source: pairs every moved point p = T_rel s with its nearest target point q
// within the radius (and the normal gate, when there is one; pairs[i] = target index or
// kNoMatch) and, with `accumulate`, sums the Gauss-Newton terms with the rotation about `pivot`:
// rows [(p - c) x n, n] for point-to-plane, [-[p - c]x, I] for point-to-point.
Sums Pass(const std::vector<Eigen::Vector3d>& source_rel, const PointCloud& target,
          const TargetTree& tree, const Eigen::Isometry3d& T_rel, double radius,
          const Eigen::Vector3d& pivot, IcpMethod method, bool accumulate, int threads,
          const NormalGate& gate, std::vector<int>& pairs) {
  const auto n = static_cast<std::ptrdiff_t>(source_rel.size());
  const auto radius_sq = static_cast<float>(radius * radius);
  const std::ptrdiff_t blocks = (n + kBlockSize - 1) / kBlockSize;
  std::vector<Sums> block_sums(static_cast<std::size_t>(blocks));
  pairs.resize(source_rel.size());
#pragma omp parallel num_threads(ThreadCount(threads))
  {
    NearestWithin result;
#pragma omp for schedule(dynamic, 1)
    for (std::ptrdiff_t block = 0; block < blocks; ++block) {
      Sums& sums = block_sums[static_cast<std::size_t>(block)];
      const std::ptrdiff_t end = std::min(n, (block + 1) * kBlockSize);
      for (std::ptrdiff_t i = block * kBlockSize; i < end; ++i) {
        const Eigen::Vector3d p = T_rel * source_rel[static_cast<std::size_t>(i)];
        if (gate.source != nullptr) {
          const Eigen::Vector3d n =
              T_rel.linear() * (*gate.source)[static_cast<std::size_t>(i)].cast<double>();
          result.Gate(gate.target, n.cast<float>(), gate.min_cos);
        }
        const int j = tree.Nearest(p, radius_sq, result);
        pairs[static_cast<std::size_t>(i)] = j;
        if (j == kNoMatch || !accumulate) continue;
        const Eigen::Vector3d q = target.points[static_cast<std::size_t>(j)].cast<double>();
        const Eigen::Vector3d d = p - q;
        sums.squared_distance += d.squaredNorm();
        ++sums.count;
        if (method == IcpMethod::kPointToPlane) {
          const Eigen::Vector3d normal =
              target.normals[static_cast<std::size_t>(j)].cast<double>().normalized();
          Vector6d J;
          J << (p - pivot).cross(normal), normal;
          const double r = normal.dot(d);
          sums.JtJ.selfadjointView<Eigen::Upper>().rankUpdate(J);
          sums.Jtr += J * r;
          sums.squared_residual += r * r;
        } else {
          Eigen::Matrix<double, 3, 6> J;
          J << MinusSkew(p - pivot), Eigen::Matrix3d::Identity();
          sums.JtJ.selfadjointView<Eigen::Upper>().rankUpdate(J.transpose());
          sums.Jtr += J.transpose() * d;
          sums.squared_residual += d.squaredNorm();
        }
      }
    }
  }
  Sums total;
  for (const Sums& sums : block_sums) total.Add(sums);
  total.JtJ.triangularView<Eigen::StrictlyLower>() = total.JtJ.transpose();
  return total;
}

// Minimum-norm solution of JtJ x = -Jtr over the eigenvalues above the floor.
Vector6d SolveTruncated(const Matrix6d& JtJ, const Vector6d& Jtr) {
  const Eigen::SelfAdjointEigenSolver<Matrix6d> solver(JtJ);
  const Vector6d& values = solver.eigenvalues();
  const double floor = kEigenvalueFloor * values(5);
  Vector6d x = Vector6d::Zero();
  if (!(values(5) > 0.0)) return x;
  for (int k = 0; k < 6; ++k) {
    if (values(k) <= floor) continue;
    const Vector6d u = solver.eigenvectors().col(k);
    x -= (u.dot(Jtr) / values(k)) * u;
  }
  return x;
}

// The part of a step x = [w, v] (rotation about the pivot, translation) along the directions the
// pairs determine well: the eigenvectors of J^T J, its rotation scaled by the pairs' RMS lever arm
// so that both halves are in metres, whose eigenvalue is at least `ratio` of the largest. A pipe's
// roll about its axis and slide along it are left out: there the pairs pin nothing, and the pose
// drifts by noise from one iteration to the next.
Vector6d WellDeterminedPart(const Matrix6d& JtJ, const Vector6d& x, double ratio) {
  const double translation_trace = JtJ.bottomRightCorner<3, 3>().trace();
  const double rotation_trace = JtJ.topLeftCorner<3, 3>().trace();
  if (!(translation_trace > 0.0 && rotation_trace > 0.0)) return x;
  const double lever_m = std::sqrt(rotation_trace / translation_trace);
  Vector6d scale;
  scale << Eigen::Vector3d::Constant(lever_m), Eigen::Vector3d::Ones();
  const Matrix6d scaled =
      scale.cwiseInverse().asDiagonal() * JtJ * scale.cwiseInverse().asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Matrix6d> solver(scaled);
  const Vector6d x_scaled = scale.cwiseProduct(x);
  Vector6d strong = Vector6d::Zero();
  for (int k = 0; k < 6; ++k) {
    if (solver.eigenvalues()(k) < ratio * solver.eigenvalues()(5)) continue;
    const Vector6d u = solver.eigenvectors().col(k);
    strong += u.dot(x_scaled) * u;
  }
  return strong.cwiseQuotient(scale);
}

// The step with a prior: minimises |J x + r|^2 / sigma^2 + (e + x)^T L (e + x), where
// e = [w, v] is the current pose's perturbation from the prior's (offset = current * prior^-1,
// its rotation vector and translation) and L the prior's information.
Vector6d SolveWithPrior(const Sums& sums, const IcpPrior& prior, const Eigen::Isometry3d& offset) {
  const double weight = 1.0 / (prior.point_sigma_m * prior.point_sigma_m);
  Vector6d e;
  const Eigen::AngleAxisd rotation(offset.linear());
  e << rotation.angle() * rotation.axis(), offset.translation();
  const Matrix6d H = weight * sums.JtJ + prior.information;
  const Vector6d g = weight * sums.Jtr + prior.information * e;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> solver(H);
  const Vector6d& values = solver.eigenvalues();
  Vector6d x = Vector6d::Zero();
  if (!(values(5) > 0.0)) return x;
  for (int k = 0; k < 6; ++k) {
    if (values(k) <= kEigenvalueFloor * values(5)) continue;  // neither points nor prior: stay
    const Vector6d u = solver.eigenvectors().col(k);
    x -= (u.dot(g) / values(k)) * u;
  }
  return x;
}

void RequireRigid(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d R = T.linear();
  if (!T.matrix().allFinite() ||
      (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 ||
      R.determinant() <= 0.0) {
    throw Error(
        "AlignIcp: T_target_source_init must be finite with a rotation (orthonormal, det +1) "
        "as its linear part");
  }
}

// T_target_source as it maps source points relative to the source origin to target points
// relative to the target origin.
Eigen::Isometry3d RelativeToOrigins(const Eigen::Isometry3d& T_target_source,
                                    const PointCloud& source, const PointCloud& target) {
  return Eigen::Translation3d(-target.origin) * T_target_source *
         Eigen::Translation3d(source.origin);
}

std::vector<Eigen::Vector3d> PointsInDouble(const PointCloud& cloud) {
  std::vector<Eigen::Vector3d> points(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) points[i] = cloud.points[i].cast<double>();
  return points;
}

// Unit normals of the source and the target for the normal gate, computed once; both empty
// when IcpOptions::max_normal_angle_rad does not gate the pairs.
struct UnitNormals {
  std::vector<Eigen::Vector3f> source;
  std::vector<Eigen::Vector3f> target;
};

UnitNormals NormalsForGate(const PointCloud& source, const PointCloud& target,
                           const IcpOptions& options) {
  UnitNormals normals;
  if (!(options.max_normal_angle_rad > 0.0)) return normals;
  if (!source.has_normals() || !target.has_normals()) {
    throw Error("AlignIcp: max_normal_angle_rad needs normals on both the source and the target");
  }
  for (const Eigen::Vector3f& n : source.normals) normals.source.push_back(n.normalized());
  for (const Eigen::Vector3f& n : target.normals) normals.target.push_back(n.normalized());
  return normals;
}

NormalGate GateOf(const UnitNormals& normals, const IcpOptions& options) {
  if (!(options.max_normal_angle_rad > 0.0)) return {};
  return {&normals.source, &normals.target,
          static_cast<float>(std::cos(options.max_normal_angle_rad))};
}

// What stays fixed through one alignment; all geometry relative to the target origin.
struct IcpProblem {
  const std::vector<Eigen::Vector3d>& source_rel;
  const PointCloud& target;
  const TargetTree& tree;
  const IcpOptions& options;
  NormalGate gate;
  Eigen::Vector3d target_centroid;
  // With a prior the linearisation is about the target origin, where the prior's information
  // is expressed; without one about the centroid, which conditions the step best.
  Eigen::Vector3d pivot;
  Eigen::Isometry3d prior_rel;  // the prior's pose; identity without a prior
  bool point_to_plane;
};

// Where the alignment stands between iterations.
struct IcpState {
  Eigen::Isometry3d T_rel;  // the current pose, relative to the origins
  int iterations = 0;       // over all stages
  bool stopped = false;     // too few pairs or degenerate pairs
};

// Buffers of the iterations, reused.
struct IcpScratch {
  std::vector<int> pairs;
  std::vector<Eigen::Vector3d> moved, matched;  // point-to-point pairs
};

// One iteration's increment and the RMS residual of the pairs it was solved from; `settled` is
// the part of the increment the convergence test measures (IcpOptions::weak_direction_ratio).
struct IcpStep {
  Eigen::Isometry3d increment;
  double rmse;
  Eigen::Isometry3d settled;
};

// One Gauss-Newton step on the point-to-plane sums; none with fewer than 3 pairs.
std::optional<IcpStep> PointToPlaneStep(const IcpProblem& problem, const Sums& sums,
                                        const Eigen::Isometry3d& T_rel) {
  if (sums.count < 3) return std::nullopt;
  const double rmse = std::sqrt(sums.squared_residual / static_cast<double>(sums.count));
  const std::optional<IcpPrior>& prior = problem.options.prior;
  const Vector6d x = prior ? SolveWithPrior(sums, *prior, T_rel * problem.prior_rel.inverse())
                           : SolveTruncated(sums.JtJ, sums.Jtr);
  const Eigen::Isometry3d increment = IncrementAbout(problem.pivot, x.head<3>(), x.tail<3>());
  const double ratio = problem.options.weak_direction_ratio;
  if (!(ratio > 0.0)) return IcpStep{increment, rmse, increment};
  const Vector6d strong = WellDeterminedPart(sums.JtJ, x, ratio);
  return IcpStep{increment, rmse,
                 IncrementAbout(problem.pivot, strong.head<3>(), strong.tail<3>())};
}

// The closed-form step on the pairs found by the last Pass; none with fewer than 3 pairs or
// collinear ones.
std::optional<IcpStep> PointToPointStep(const IcpProblem& problem, const Eigen::Isometry3d& T_rel,
                                        IcpScratch& scratch) {
  std::vector<Eigen::Vector3d>& moved = scratch.moved;
  std::vector<Eigen::Vector3d>& matched = scratch.matched;
  moved.clear();
  matched.clear();
  for (std::size_t i = 0; i < problem.source_rel.size(); ++i) {
    if (scratch.pairs[i] == kNoMatch) continue;
    moved.push_back(T_rel * problem.source_rel[i]);
    matched.push_back(
        problem.target.points[static_cast<std::size_t>(scratch.pairs[i])].cast<double>());
  }
  if (moved.size() < 3) return std::nullopt;
  const SvdAlignment step = AlignSvd(moved, matched);
  if (step.status != SvdAlignmentStatus::kSuccess) return std::nullopt;
  double squared = 0.0;
  for (std::size_t i = 0; i < moved.size(); ++i) squared += (moved[i] - matched[i]).squaredNorm();
  return IcpStep{step.T_target_source, std::sqrt(squared / static_cast<double>(moved.size())),
                 step.T_target_source};
}

// Pairs the source moved by T_rel with the target within `radius` and solves for the next
// increment; none when the pairs cannot give one.
std::optional<IcpStep> Iterate(const IcpProblem& problem, double radius,
                               const Eigen::Isometry3d& T_rel, IcpScratch& scratch) {
  const IcpOptions& options = problem.options;
  const Sums sums =
      Pass(problem.source_rel, problem.target, problem.tree, T_rel, radius, problem.pivot,
           options.method, problem.point_to_plane, options.threads, problem.gate, scratch.pairs);
  return problem.point_to_plane ? PointToPlaneStep(problem, sums, T_rel)
                                : PointToPointStep(problem, T_rel, scratch);
}

// A stage's lowest residual so far, the pose it was measured at, and the iterations since
// (IcpOptions::stall_iterations).
struct StallWatch {
  double lowest_rmse = std::numeric_limits<double>::infinity();
  Eigen::Isometry3d T_lowest;
  int since_lowest = 0;

  // Whether the stage has stalled with `rmse`, measured at T_rel.
  bool Stalled(double rmse, const Eigen::Isometry3d& T_rel, const IcpOptions& options) {
    if (rmse < lowest_rmse * (1.0 - options.relative_rmse_tolerance)) {
      lowest_rmse = rmse;
      T_lowest = T_rel;
      since_lowest = 0;
      return false;
    }
    return options.stall_iterations > 0 && ++since_lowest >= options.stall_iterations;
  }
};

// Whether a stage has converged: the increment (its settled part) is below both step tolerances,
// or the residual changed by at most relative_rmse_tolerance of the previous one (NaN: none yet);
// the tolerances times `scale`.
bool StageConverged(const IcpProblem& problem, const IcpStep& step, double previous_rmse,
                    double scale) {
  const IcpOptions& options = problem.options;
  const Eigen::Vector3d& centroid = problem.target_centroid;
  const double rotation_step = Eigen::AngleAxisd(step.settled.linear()).angle();
  const double translation_step = (step.settled * centroid - centroid).norm();
  const bool small_step = rotation_step < scale * options.rotation_tolerance_rad &&
                          translation_step < scale * options.translation_tolerance_m;
  const bool flat_rmse =
      std::isfinite(previous_rmse) && std::abs(previous_rmse - step.rmse) <=
                                          scale * options.relative_rmse_tolerance * previous_rmse;
  return small_step || flat_rmse;
}

// Iterates with the pairs within `radius` until the stage converges (returns true), stalls,
// reaches an iteration cap or stops.
bool RunStage(const IcpProblem& problem, double radius, bool last_stage, IcpState& state,
              IcpScratch& scratch) {
  const IcpOptions& options = problem.options;
  const double scale = last_stage ? 1.0 : options.early_stage_tolerance_scale;
  double previous_rmse = std::numeric_limits<double>::quiet_NaN();
  StallWatch stall{.T_lowest = state.T_rel};
  for (int k = 0; k < options.max_iterations_per_stage; ++k) {
    if (state.iterations >= options.max_iterations) break;
    const std::optional<IcpStep> step = Iterate(problem, radius, state.T_rel, scratch);
    if (!step) {
      // Nothing to match: with a prior, the prior is the answer.
      if (problem.point_to_plane && options.prior) state.T_rel = problem.prior_rel;
      state.stopped = true;
      return false;
    }
    if (stall.Stalled(step->rmse, state.T_rel, options)) {
      state.T_rel = stall.T_lowest;
      ++state.iterations;
      return false;
    }
    state.T_rel = step->increment * state.T_rel;
    ++state.iterations;
    if (StageConverged(problem, *step, previous_rmse, scale)) return true;
    previous_rmse = step->rmse;
  }
  return false;
}

// Fitness, RMSE and information at T_rel, with the last stage's distance; the information's
// rotation is about the target origin.
RegistrationResult Evaluate(const IcpProblem& problem, const PointCloud& source,
                            const Eigen::Isometry3d& T_rel, IcpScratch& scratch) {
  const IcpOptions& options = problem.options;
  const PointCloud& target = problem.target;
  const Sums sums = Pass(problem.source_rel, target, problem.tree, T_rel,
                         options.max_correspondence_distance_m.back(), Eigen::Vector3d::Zero(),
                         options.method, true, options.threads, problem.gate, scratch.pairs);
  RegistrationResult result;
  result.T_target_source =
      Eigen::Translation3d(target.origin) * T_rel * Eigen::Translation3d(-source.origin);
  result.fitness = static_cast<double>(sums.count) / static_cast<double>(source.size());
  result.inlier_rmse =
      sums.count == 0 ? 0.0 : std::sqrt(sums.squared_distance / static_cast<double>(sums.count));
  if (problem.point_to_plane && sums.count > 0) {
    result.inlier_plane_rmse = std::sqrt(sums.squared_residual / static_cast<double>(sums.count));
  }
  result.information = sums.JtJ;
  return result;
}

}  // namespace

void IcpOptions::Check() const {
  const OptionChecks check("IcpOptions");
  check.Require(method == IcpMethod::kPointToPoint || method == IcpMethod::kPointToPlane, "method",
                "kPointToPoint or kPointToPlane", static_cast<int>(method));
  check.GreaterThan("max_iterations", max_iterations, 0);
  check.GreaterThan("max_iterations_per_stage", max_iterations_per_stage, 0);
  check.Require(!max_correspondence_distance_m.empty(), "max_correspondence_distance_m",
                "at least one distance", "none");
  for (std::size_t s = 0; s < max_correspondence_distance_m.size(); ++s) {
    const double d = max_correspondence_distance_m[s];
    const std::string field = "max_correspondence_distance_m[" + std::to_string(s) + "]";
    check.Positive(field, d, "m");
    if (s > 0 && d > max_correspondence_distance_m[s - 1]) {
      check.Fail(field,
                 "a distance no larger than the previous stage's (" +
                     OptionValueText(max_correspondence_distance_m[s - 1]) + " m)",
                 OptionValueText(d));
    }
  }
  check.NonNegative("rotation_tolerance_rad", rotation_tolerance_rad, "rad");
  check.NonNegative("translation_tolerance_m", translation_tolerance_m, "m");
  check.InRange("weak_direction_ratio", weak_direction_ratio, 0.0, 1.0, Interval::kOpenHigh);
  if (weak_direction_ratio > 0.0) {
    check.Require(method == IcpMethod::kPointToPlane && !prior, "weak_direction_ratio",
                  "0 unless point-to-plane without a prior", weak_direction_ratio);
  }
  // A relative change of the whole residual is no tolerance (and would make every iteration a
  // stall, stall_iterations counting a residual as lower only by this fraction).
  check.InRange("relative_rmse_tolerance", relative_rmse_tolerance, 0.0, 1.0, Interval::kOpenHigh);
  check.AtLeast("early_stage_tolerance_scale", early_stage_tolerance_scale, 1.0);
  check.AtLeast("stall_iterations", stall_iterations, 0, "(0 = off)");
  check.AtLeast("threads", threads, 0, "(0 = OpenMP's default)");
  check.Require(max_normal_angle_rad >= 0.0 && max_normal_angle_rad <= std::numbers::pi,
                "max_normal_angle_rad", "in [0, pi] rad", max_normal_angle_rad);
  if (prior) {
    check.Require(method == IcpMethod::kPointToPlane, "prior",
                  "point-to-plane (method kPointToPlane)", "point-to-point");
    check.Positive("prior.point_sigma_m", prior->point_sigma_m, "m");
    const Matrix6d& info = prior->information;
    check.Require(info.allFinite() && info.isApprox(info.transpose(), 1e-9) &&
                      Eigen::SelfAdjointEigenSolver<Matrix6d>(info).eigenvalues().minCoeff() >=
                          -1e-9 * info.cwiseAbs().maxCoeff(),
                  "prior.information", "a finite, symmetric, positive semi-definite 6x6 matrix");
  }
}

struct IcpTarget::Tree {
  Tree(const PointCloud& cloud, double grid_radius_m, double grid_cell_m, int threads)
      : tree(cloud, grid_radius_m, grid_cell_m, threads) {}
  TargetTree tree;
};

IcpTarget::IcpTarget(const PointCloud& cloud, double grid_radius_m, double grid_cell_m, int threads)
    : cloud_(cloud) {
  RequireValidCloud(cloud, "AlignIcp: target", 3);
  if (!(grid_radius_m >= 0.0 && std::isfinite(grid_radius_m))) {
    throw Error("IcpTarget: grid_radius_m must be finite and >= 0, got " +
                std::to_string(grid_radius_m));
  }
  if (!(grid_cell_m >= 0.0 && grid_cell_m <= grid_radius_m)) {
    throw Error("IcpTarget: grid_cell_m must be in [0, grid_radius_m], got " +
                std::to_string(grid_cell_m));
  }
  tree_ = std::make_unique<Tree>(cloud, grid_radius_m, grid_cell_m, threads);
  centroid_rel_.setZero();
  for (const Eigen::Vector3f& q : cloud.points) centroid_rel_ += q.cast<double>();
  centroid_rel_ /= static_cast<double>(cloud.size());
}

IcpTarget::~IcpTarget() = default;

const NearestGrid* IcpTarget::grid() const { return tree_->tree.grid(); }

RegistrationResult AlignIcp(const PointCloud& source, const PointCloud& target,
                            const Eigen::Isometry3d& T_target_source_init,
                            const IcpOptions& options) {
  options.Check();
  RequireValidCloud(source, "AlignIcp: source", 3);
  return AlignIcp(source, IcpTarget(target, 0.0, 0.0, options.threads), T_target_source_init,
                  options);
}

RegistrationResult AlignIcp(const PointCloud& source, const IcpTarget& prepared,
                            const Eigen::Isometry3d& T_target_source_init,
                            const IcpOptions& options) {
  options.Check();
  RequireValidCloud(source, "AlignIcp: source", 3);
  const PointCloud& target = prepared.cloud_;
  if (options.method == IcpMethod::kPointToPlane && !target.has_normals()) {
    throw Error("AlignIcp: target has no normals; point-to-plane needs one per target point");
  }
  RequireRigid(T_target_source_init);
  const UnitNormals normals = NormalsForGate(source, target, options);
  const std::optional<IcpPrior>& prior = options.prior;
  if (prior) RequireRigid(prior->T_target_source);

  // Everything below is relative to the target origin: T_rel maps source points relative to
  // their origin to target points relative to theirs.
  const std::vector<Eigen::Vector3d> source_rel = PointsInDouble(source);
  const Eigen::Vector3d& target_centroid = prepared.centroid_rel_;
  const IcpProblem problem{
      .source_rel = source_rel,
      .target = target,
      .tree = prepared.tree_->tree,
      .options = options,
      .gate = GateOf(normals, options),
      .target_centroid = target_centroid,
      .pivot = prior ? Eigen::Vector3d::Zero() : target_centroid,
      .prior_rel = prior ? RelativeToOrigins(prior->T_target_source, source, target)
                         : Eigen::Isometry3d::Identity(),
      .point_to_plane = options.method == IcpMethod::kPointToPlane};

  IcpState state{.T_rel = RelativeToOrigins(T_target_source_init, source, target)};
  IcpScratch scratch;
  bool converged = false;  // the last stage's
  const std::size_t stages = options.max_correspondence_distance_m.size();
  for (std::size_t stage = 0; stage < stages && !state.stopped; ++stage) {
    const bool stage_converged = RunStage(problem, options.max_correspondence_distance_m[stage],
                                          stage + 1 == stages, state, scratch);
    if (stage + 1 == stages) converged = stage_converged && !state.stopped;
  }
  RegistrationResult result = Evaluate(problem, source, state.T_rel, scratch);
  result.iterations = state.iterations;
  result.converged = converged;
  return result;
}

}  // namespace uwscan::perception
