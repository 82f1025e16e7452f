#include "mapping/change/tile_placement.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/cloud/flann_distance.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

// The poses a point was seen from, each with its equal share.
struct SeenFrom {
  std::vector<std::size_t> poses;
  double share = 0.0;
};

// The survey's pose positions (about the first), for the poses near a point: its nearest by
// kd-tree, then those within a reach by a scan of the positions sorted along their widest axis.
// Distances are FLANN's float squared distances, as the kd-tree's.
class PosePositions {
 public:
  explicit PosePositions(const Survey& survey)
      : origin_(survey.poses.front().translation()),
        positions_(Relative(survey, origin_)),
        index_(positions_) {
    Eigen::Array3f lo = positions_.front().array(), hi = lo;
    for (const Eigen::Vector3f& p : positions_) {
      lo = lo.min(p.array());
      hi = hi.max(p.array());
    }
    (hi - lo).maxCoeff(&axis_);
    for (std::size_t i = 0; i < positions_.size(); ++i) by_axis_.push_back(i);
    std::sort(by_axis_.begin(), by_axis_.end(), [&](std::size_t a, std::size_t b) {
      return positions_[a][axis_] < positions_[b][axis_];
    });
    for (const std::size_t i : by_axis_) along_axis_.push_back(positions_[i][axis_]);
  }

  // The poses no more than within_m farther from p than the nearest one, sorted.
  std::vector<std::size_t> Near(const Eigen::Vector3d& p, double within_m) const {
    const Eigen::Vector3f q = (p - origin_).cast<float>();
    std::vector<std::uint32_t> nearest;
    std::vector<float> d2;
    index_.Query(q, 1, nearest, d2);
    const double reach_m = std::sqrt(static_cast<double>(d2.front())) + within_m;
    // A pose farther than the reach along the axis is farther than it in space; a float margin
    // keeps every pose the exact test below may take.
    const float margin = static_cast<float>(reach_m * (1.0 + 1e-5)) + 1e-6f;
    const auto first = std::lower_bound(along_axis_.begin(), along_axis_.end(), q[axis_] - margin);
    const auto last = std::upper_bound(first, along_axis_.end(), q[axis_] + margin);
    std::vector<std::size_t> poses;
    for (auto it = first; it != last; ++it) {
      const std::size_t i = by_axis_[static_cast<std::size_t>(it - along_axis_.begin())];
      const Eigen::Vector3f& x = positions_[i];
      const float d = perception::FlannSquaredDistance(q.x(), q.y(), q.z(), x.x(), x.y(), x.z());
      if (std::sqrt(static_cast<double>(d)) <= reach_m) poses.push_back(i);
    }
    std::sort(poses.begin(), poses.end());
    return poses;
  }

 private:
  static std::vector<Eigen::Vector3f> Relative(const Survey& survey,
                                               const Eigen::Vector3d& origin) {
    std::vector<Eigen::Vector3f> positions;
    for (const Eigen::Isometry3d& T : survey.poses)
      positions.push_back((T.translation() - origin).cast<float>());
    return positions;
  }

  Eigen::Vector3d origin_;
  std::vector<Eigen::Vector3f> positions_;
  perception::KnnIndex index_;
  int axis_ = 0;
  std::vector<std::size_t> by_axis_;  // pose indices sorted along axis_
  std::vector<float> along_axis_;     // their coordinates along it
};

// For each point, the poses no more than seen_within_m farther from it than the nearest one.
std::vector<SeenFrom> PosesThatSaw(const Survey& survey,
                                   const std::vector<Eigen::Vector3d>& points_S,
                                   double seen_within_m) {
  const PosePositions positions(survey);
  std::vector<SeenFrom> seen(points_S.size());
#pragma omp parallel for schedule(dynamic, 256)
  for (std::size_t c = 0; c < points_S.size(); ++c) {
    seen[c].poses = positions.Near(points_S[c], seen_within_m);
    seen[c].share = 1.0 / static_cast<double>(seen[c].poses.size());
  }
  return seen;
}

Eigen::Matrix3d Cross(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

// Consecutive positions first..last in a tile's poses.
struct Run {
  std::size_t first = 0, last = 0;
};

// One tile's poses (sorted), the weight of each (the mean over the tile's points of their
// shares), and what the point-by-point variance needs of the poses' joint covariance, with each
// pose's error e = [w, v] about its own position moved to a twist about the tile's `origin`:
// xi_i = B_i e_i = [w, v + (t_i - origin) x w], so that every pose displaces a point p along n by
// g(p)^T xi_i with the same g(p) = [(p - origin) x n, n].
// Its points' distinct sets of poses are kept as runs of the tile's poses (one per pass over the
// point), so that a set's sum over its pairs of poses costs one difference per run and pose.
class TilePoses {
 public:
  std::vector<std::size_t> poses;
  std::vector<double> weights;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();

  void SetOrigin(const Survey& survey) {
    for (const std::size_t pose : poses) origin += survey.poses[pose].translation();
    origin /= static_cast<double>(poses.size());
    to_twist_.assign(poses.size(), Matrix6d::Identity());
    for (std::size_t i = 0; i < poses.size(); ++i)
      to_twist_[i].block<3, 3>(3, 0) = Cross(survey.poses[poses[i]].translation() - origin);
    with_tile_.assign(poses.size(), Matrix6d::Zero());
    sets_holding_.assign(poses.size(), {});
  }

  // The index of a point's set of poses (all in the tile) among the tile's distinct sets.
  std::size_t AddSet(const SeenFrom& seen) {
    const auto [at, added] = set_index_.try_emplace(seen.poses, runs_.size());
    if (!added) return at->second;
    std::vector<Run> runs;
    for (const std::size_t pose : seen.poses) {
      const std::size_t i = *Position(pose);
      if (runs.empty() || i != runs.back().last + 1)
        runs.push_back({i, i});
      else
        runs.back().last = i;
      sets_holding_[i].push_back(runs_.size());
    }
    runs_.push_back(std::move(runs));
    shares_.push_back(seen.share);
    own_.push_back(Matrix6d::Zero());
    return at->second;
  }

  // Pose `pose`'s columns Cov(e_j, e_pose) for every pose j of the survey, when it is one of the
  // tile's: its terms of with_tile_j += w_i Cov(e_j, e_i) B_i^T, and of every set holding it,
  // own += sum over the set's poses a of B_a Cov(e_a, e_i) B_i^T (a run as running totals).
  void AddColumnsOf(std::size_t pose, const Eigen::Ref<const Eigen::MatrixXd>& columns) {
    const std::optional<std::size_t> at = Position(pose);
    if (!at) return;
    const std::size_t i = *at;
    const auto block = [&](std::size_t j) -> Matrix6d {
      return columns.middleRows(6 * static_cast<Eigen::Index>(poses[j]), 6);
    };
    const Matrix6d right = weights[i] * to_twist_[i].transpose();
    for (std::size_t j = 0; j < poses.size(); ++j) with_tile_[j] += block(j) * right;
    if (sets_holding_[i].empty()) return;
    std::vector<Matrix6d> totals(poses.size() + 1, Matrix6d::Zero());
    for (std::size_t j = 0; j < poses.size(); ++j)
      totals[j + 1] = totals[j] + to_twist_[j] * block(j) * to_twist_[i].transpose();
    for (const std::size_t k : sets_holding_[i])
      for (const Run& run : runs_[k]) own_[k] += totals[run.last + 1] - totals[run.first];
  }

  // Once every pose's columns are in: B_j applied to the with_tile sums, the tile's mean twist.
  void Finish() {
    for (std::size_t i = 0; i < poses.size(); ++i) {
      with_tile_[i] = to_twist_[i] * with_tile_[i];
      tile_ += weights[i] * with_tile_[i];
    }
  }

  // Cov(mean twist of set k's poses - the tile's mean twist), after Finish.
  Matrix6d Residual(std::size_t k) const {
    Matrix6d cross = Matrix6d::Zero();
    for (const Run& run : runs_[k])
      for (std::size_t i = run.first; i <= run.last; ++i) cross += with_tile_[i];
    const double share = shares_[k];
    return share * share * own_[k] - share * (cross + cross.transpose()) + tile_;
  }
  std::size_t set_count() const { return runs_.size(); }

 private:
  std::optional<std::size_t> Position(std::size_t pose) const {
    const auto it = std::lower_bound(poses.begin(), poses.end(), pose);
    if (it == poses.end() || *it != pose) return std::nullopt;
    return static_cast<std::size_t>(it - poses.begin());
  }

  std::vector<Matrix6d> to_twist_;    // B_i per pose
  std::vector<Matrix6d> with_tile_;   // per pose i: sum_j w_j Cov(xi_i, xi_j), once finished
  Matrix6d tile_ = Matrix6d::Zero();  // Cov of the mean twist, sum_ij w_i w_j Cov(xi_i, xi_j)
  std::map<std::vector<std::size_t>, std::size_t> set_index_;
  std::vector<std::vector<Run>> runs_;                  // per set
  std::vector<double> shares_;                          // per set: 1 / its number of poses
  std::vector<Matrix6d> own_;                           // per set: sum over its pairs of poses
  std::vector<std::vector<std::size_t>> sets_holding_;  // per pose: the sets holding it
};

std::map<long, TilePoses> PosesOfTiles(const Survey& survey, const std::vector<SeenFrom>& seen,
                                       const std::vector<long>& tile_of) {
  std::map<long, std::vector<double>> sums;  // per tile and pose: its points' shares
  std::map<long, int> points;
  for (std::size_t c = 0; c < seen.size(); ++c) {
    const long tile = std::max(tile_of[c], -1L);
    ++points[tile];
    std::vector<double>& sum = sums[tile];
    if (sum.empty()) sum.assign(survey.poses.size(), 0.0);
    for (const std::size_t pose : seen[c].poses) sum[pose] += seen[c].share;
  }
  std::map<long, TilePoses> tiles;
  for (const auto& [tile, per_pose] : sums) {
    TilePoses& t = tiles[tile];
    for (std::size_t pose = 0; pose < per_pose.size(); ++pose) {
      if (per_pose[pose] == 0.0) continue;
      t.poses.push_back(pose);
      t.weights.push_back(per_pose[pose] / points[tile]);
    }
    t.SetOrigin(survey);
  }
  return tiles;
}

// The tiles' sums over the poses' joint covariance, each pose's 6 columns solved once: in
// batches, the batches of a round in parallel, then added tile by tile (the tiles in parallel,
// each in pose order), so the bits do not depend on the threads. False when it is singular.
bool AccumulateCovariances(const JointPoseUncertainty& uncertainty,
                           const std::vector<TilePoses*>& tiles) {
  constexpr std::size_t kBatch = 32;
  std::vector<std::size_t> all;
  for (const TilePoses* t : tiles) all.insert(all.end(), t->poses.begin(), t->poses.end());
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  const std::size_t per_round = kBatch * static_cast<std::size_t>(omp_get_max_threads());
  for (std::size_t round = 0; round < all.size(); round += per_round) {
    std::vector<std::vector<std::size_t>> batches;
    for (std::size_t b = round; b < std::min(all.size(), round + per_round); b += kBatch)
      batches.emplace_back(
          all.begin() + static_cast<std::ptrdiff_t>(b),
          all.begin() + static_cast<std::ptrdiff_t>(std::min(all.size(), b + kBatch)));
    std::vector<std::optional<Eigen::MatrixXd>> columns(batches.size());
#pragma omp parallel for schedule(static, 1)
    for (std::size_t k = 0; k < batches.size(); ++k)
      columns[k] = uncertainty.CovarianceColumns(batches[k]);
    if (std::any_of(columns.begin(), columns.end(), [](const auto& c) { return !c; })) return false;
#pragma omp parallel for schedule(dynamic, 1)
    for (std::size_t t = 0; t < tiles.size(); ++t)
      for (std::size_t k = 0; k < batches.size(); ++k)
        for (std::size_t c = 0; c < batches[k].size(); ++c)
          tiles[t]->AddColumnsOf(batches[k][c],
                                 columns[k]->middleCols(6 * static_cast<Eigen::Index>(c), 6));
  }
  for (TilePoses* t : tiles) t->Finish();
  return true;
}

}  // namespace

std::vector<double> TileRelativePoseSigmas(const Survey& survey,
                                           const std::vector<Eigen::Vector3d>& points_S,
                                           const std::vector<Eigen::Vector3d>& normals_S,
                                           const std::vector<long>& tile_of, double seen_within_m) {
  if (points_S.size() != normals_S.size() || points_S.size() != tile_of.size())
    throw Error("TileRelativePoseSigmas: points, normals and tiles differ in number");
  if (!(seen_within_m >= 0.0)) throw Error("TileRelativePoseSigmas: seen_within_m must be >= 0");
  std::vector<double> sigma(points_S.size(), 0.0);
  if (!survey.joint_uncertainty || survey.poses.empty() || points_S.empty()) return sigma;
  if (survey.joint_uncertainty->pose_count() != survey.poses.size()) {
    throw Error(survey.name + ": its joint pose uncertainty holds " +
                std::to_string(survey.joint_uncertainty->pose_count()) + " poses, its trajectory " +
                std::to_string(survey.poses.size()));
  }
  const std::vector<SeenFrom> seen = PosesThatSaw(survey, points_S, seen_within_m);
  std::map<long, TilePoses> tiles = PosesOfTiles(survey, seen, tile_of);
  std::vector<TilePoses*> order;
  std::map<long, std::size_t> ordinal;
  for (auto& [id, t] : tiles) {
    ordinal[id] = order.size();
    order.push_back(&t);
  }
  // Neighbouring points are mostly seen from the same poses: each (tile, poses) once.
  std::vector<std::pair<std::size_t, std::size_t>> set_of(points_S.size());
  for (std::size_t c = 0; c < points_S.size(); ++c) {
    const std::size_t t = ordinal.at(std::max(tile_of[c], -1L));
    set_of[c] = {t, order[t]->AddSet(seen[c])};
  }
  if (!AccumulateCovariances(*survey.joint_uncertainty, order)) return sigma;
  std::vector<std::vector<Matrix6d>> residuals(order.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (std::size_t t = 0; t < order.size(); ++t)
    for (std::size_t k = 0; k < order[t]->set_count(); ++k)
      residuals[t].push_back(order[t]->Residual(k));
  for (std::size_t c = 0; c < points_S.size(); ++c) {
    const auto [t, k] = set_of[c];
    Vector6d g;
    g << (points_S[c] - order[t]->origin).cross(normals_S[c]), normals_S[c];
    sigma[c] = std::sqrt(std::max(0.0, g.dot(residuals[t][k] * g)));
  }
  return sigma;
}

}  // namespace uwscan::mapping
