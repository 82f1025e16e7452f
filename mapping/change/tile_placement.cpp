#include "mapping/change/tile_placement.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>

#include "perception/cloud/cloud_neighbors.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

// The poses a point was seen from, each with its equal share.
struct SeenFrom {
  std::vector<std::size_t> poses;
  double share = 0.0;
};

// For each point, the poses no more than seen_within_m farther from it than the nearest one.
std::vector<SeenFrom> PosesThatSaw(const Survey& survey,
                                   const std::vector<Eigen::Vector3d>& points_S,
                                   double seen_within_m) {
  const Eigen::Vector3d origin = survey.poses.front().translation();
  std::vector<Eigen::Vector3f> positions;
  for (const Eigen::Isometry3d& T : survey.poses)
    positions.push_back((T.translation() - origin).cast<float>());
  const perception::KnnIndex index(positions);
  const int count = static_cast<int>(positions.size());
  std::vector<SeenFrom> seen(points_S.size());
#pragma omp parallel for schedule(dynamic, 256)
  for (std::size_t c = 0; c < points_S.size(); ++c) {
    const Eigen::Vector3f q = (points_S[c] - origin).cast<float>();
    std::vector<std::uint32_t> found;
    std::vector<float> d2;
    // Widen the search until its farthest pose lies beyond the reach (or every pose is in).
    for (int k = std::min(32, count);; k = std::min(2 * k, count)) {
      index.Query(q, k, found, d2);
      const double reach_m = std::sqrt(static_cast<double>(d2.front())) + seen_within_m;
      if (k == count || std::sqrt(static_cast<double>(d2.back())) > reach_m) {
        for (std::size_t j = 0; j < found.size(); ++j)
          if (std::sqrt(static_cast<double>(d2[j])) <= reach_m) seen[c].poses.push_back(found[j]);
        break;
      }
    }
    std::sort(seen[c].poses.begin(), seen[c].poses.end());
    seen[c].share = 1.0 / static_cast<double>(seen[c].poses.size());
  }
  return seen;
}

Eigen::Matrix3d Cross(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

// One tile's poses (sorted), the weight of each (the mean over the tile's points of their
// shares), and what the point-by-point variance needs of the poses' joint covariance, with each
// pose's error e = [w, v] about its own position moved to a twist about the tile's `origin`:
// xi_i = B_i e_i = [w, v + (t_i - origin) x w], so that every pose displaces a point p along n by
// g(p)^T xi_i with the same g(p) = [(p - origin) x n, n].
struct TilePoses {
  std::vector<std::size_t> poses;
  std::vector<double> weights;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  std::vector<Matrix6d> to_twist;    // B_i per pose
  std::vector<Matrix6d> with_tile;   // per pose i: sum_j w_j Cov(xi_i, xi_j), once accumulated
  Matrix6d tile = Matrix6d::Zero();  // Cov of the tile's mean twist, sum_ij w_i w_j Cov(xi_i, xi_j)

  std::size_t Position(std::size_t pose) const {
    return static_cast<std::size_t>(std::lower_bound(poses.begin(), poses.end(), pose) -
                                    poses.begin());
  }
  void SetOrigin(const Survey& survey) {
    for (const std::size_t pose : poses) origin += survey.poses[pose].translation();
    origin /= static_cast<double>(poses.size());
    to_twist.assign(poses.size(), Matrix6d::Identity());
    for (std::size_t i = 0; i < poses.size(); ++i)
      to_twist[i].block<3, 3>(3, 0) = Cross(survey.poses[poses[i]].translation() - origin);
    with_tile.assign(poses.size(), Matrix6d::Zero());
  }
};

std::map<long, TilePoses> PosesOfTiles(const Survey& survey, const std::vector<SeenFrom>& seen,
                                       const std::vector<long>& tile_of) {
  std::map<long, std::map<std::size_t, double>> sums;
  std::map<long, int> points;
  for (std::size_t c = 0; c < seen.size(); ++c) {
    const long tile = std::max(tile_of[c], -1L);
    ++points[tile];
    for (const std::size_t pose : seen[c].poses) sums[tile][pose] += seen[c].share;
  }
  std::map<long, TilePoses> tiles;
  for (const auto& [tile, per_pose] : sums) {
    TilePoses& t = tiles[tile];
    for (const auto& [pose, sum] : per_pose) {
      t.poses.push_back(pose);
      t.weights.push_back(sum / points[tile]);
    }
    t.SetOrigin(survey);
  }
  return tiles;
}

// What the residuals need of the poses' joint covariance, each pose's 6 columns solved once (in
// batches, the batches of a round in parallel, then summed in pose order, so the bits do not
// depend on the threads): Cov(e_a, e_b) for every two poses one point was seen from, and each
// tile's weighted sums (TilePoses::with_tile, tile).
class CovarianceSums {
 public:
  CovarianceSums(const Survey& survey, const std::vector<SeenFrom>& seen,
                 std::map<long, TilePoses>& tiles)
      : tiles_(tiles), pose_count_(survey.poses.size()) {
    for (auto& [id, t] : tiles_)
      for (std::size_t i = 0; i < t.poses.size(); ++i)
        tiles_of_pose_[t.poses[i]].push_back({&t, i});
    // Each distinct set of poses once (neighbouring points share theirs).
    std::set<std::vector<std::size_t>> sets;
    for (const SeenFrom& s : seen) sets.insert(s.poses);
    co_seen_.assign(pose_count_ * pose_count_, false);
    for (const std::vector<std::size_t>& poses : sets)
      for (const std::size_t a : poses)
        for (const std::size_t b : poses) co_seen_[Key(a, b)] = true;
    known_ = Accumulate(*survey.joint_uncertainty);
    for (auto& [id, t] : tiles_) {
      for (std::size_t i = 0; i < t.poses.size(); ++i) {
        t.with_tile[i] = t.to_twist[i] * t.with_tile[i];
        t.tile += t.weights[i] * t.with_tile[i];
      }
    }
  }
  bool known() const { return known_; }

  // Cov(mean twist of the point's poses - the tile's mean twist) for each of `seen`, all in
  // `tile`: the twists' pair blocks each made once, in a table of the tile's poses.
  std::vector<Matrix6d> Residuals(const TilePoses& tile,
                                  const std::vector<const SeenFrom*>& seen) const {
    const std::size_t m = tile.poses.size();
    std::vector<Matrix6d> twist(m * m);
    std::vector<char> made(m * m, 0);
    std::vector<Matrix6d> out;
    for (const SeenFrom* s : seen) {
      Matrix6d own = Matrix6d::Zero(), cross = Matrix6d::Zero();
      for (const std::size_t a : s->poses) {
        const std::size_t i = tile.Position(a);
        cross += tile.with_tile[i];
        for (const std::size_t b : s->poses) {
          const std::size_t j = tile.Position(b);
          if (!made[i * m + j]) {
            twist[i * m + j] =
                tile.to_twist[i] * pairs_.at(Key(a, b)) * tile.to_twist[j].transpose();
            made[i * m + j] = 1;
          }
          own += twist[i * m + j];
        }
      }
      out.push_back(s->share * s->share * own - s->share * (cross + cross.transpose()) + tile.tile);
    }
    return out;
  }

 private:
  static constexpr std::size_t kBatch = 32;

  bool Accumulate(const JointPoseUncertainty& uncertainty) {
    std::vector<std::size_t> all;
    for (const auto& [pose, where] : tiles_of_pose_) all.push_back(pose);
    const int threads = omp_get_max_threads();
    for (std::size_t round = 0; round < all.size(); round += kBatch * threads) {
      std::vector<std::vector<std::size_t>> batches;
      for (std::size_t b = round; b < std::min(all.size(), round + kBatch * threads); b += kBatch)
        batches.emplace_back(
            all.begin() + static_cast<std::ptrdiff_t>(b),
            all.begin() + static_cast<std::ptrdiff_t>(std::min(all.size(), b + kBatch)));
      std::vector<std::optional<Eigen::MatrixXd>> columns(batches.size());
#pragma omp parallel for schedule(static, 1)
      for (std::size_t k = 0; k < batches.size(); ++k)
        columns[k] = uncertainty.CovarianceColumns(batches[k]);
      for (std::size_t k = 0; k < batches.size(); ++k) {
        if (!columns[k]) return false;
        for (std::size_t c = 0; c < batches[k].size(); ++c)
          AddColumnsOf(batches[k][c], columns[k]->middleCols(6 * static_cast<Eigen::Index>(c), 6));
      }
    }
    return true;
  }

  // Pose i's columns Cov(e_j, e_i) for every pose j: the pairs it is in, and its terms of the
  // tiles' sums, with_tile_j += w_i Cov(e_j, e_i) B_i^T (B_j applied once all are in).
  void AddColumnsOf(std::size_t i, const Eigen::Ref<const Eigen::MatrixXd>& columns) {
    const auto block = [&](std::size_t j) -> Matrix6d {
      return columns.middleRows(6 * static_cast<Eigen::Index>(j), 6);
    };
    for (std::size_t j = 0; j < pose_count_; ++j)
      if (co_seen_[Key(j, i)]) pairs_[Key(j, i)] = block(j);
    for (const auto& [t, position] : tiles_of_pose_.at(i)) {
      const Matrix6d right = t->weights[position] * t->to_twist[position].transpose();
      for (std::size_t j = 0; j < t->poses.size(); ++j)
        t->with_tile[j] += block(t->poses[j]) * right;
    }
  }

  std::size_t Key(std::size_t a, std::size_t b) const { return a * pose_count_ + b; }

  std::map<long, TilePoses>& tiles_;
  std::map<std::size_t, std::vector<std::pair<TilePoses*, std::size_t>>> tiles_of_pose_;
  std::size_t pose_count_ = 0;
  std::vector<bool> co_seen_;                        // Key(a, b): one point seen from both
  std::unordered_map<std::size_t, Matrix6d> pairs_;  // Key(a, b): Cov(e_a, e_b), when co_seen_
  bool known_ = false;
};

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
  const CovarianceSums sums(survey, seen, tiles);
  if (!sums.known()) return sigma;
  // Neighbouring points are mostly seen from the same poses: each (tile, poses) once.
  std::map<std::pair<long, std::vector<std::size_t>>, std::size_t> distinct;
  std::vector<std::size_t> residual_of(points_S.size());
  std::vector<std::size_t> first_point;
  for (std::size_t c = 0; c < points_S.size(); ++c) {
    const auto [at, added] =
        distinct.try_emplace({std::max(tile_of[c], -1L), seen[c].poses}, first_point.size());
    if (added) first_point.push_back(c);
    residual_of[c] = at->second;
  }
  // By tile, in parallel: each tile's table of pair blocks is its own.
  std::vector<long> tile_ids;
  for (const auto& [id, t] : tiles) tile_ids.push_back(id);
  std::vector<Matrix6d> residuals(first_point.size());
#pragma omp parallel for schedule(dynamic, 1)
  for (std::size_t t = 0; t < tile_ids.size(); ++t) {
    std::vector<std::size_t> ks;
    std::vector<const SeenFrom*> of_tile;
    for (std::size_t k = 0; k < first_point.size(); ++k) {
      if (std::max(tile_of[first_point[k]], -1L) != tile_ids[t]) continue;
      ks.push_back(k);
      of_tile.push_back(&seen[first_point[k]]);
    }
    const std::vector<Matrix6d> r = sums.Residuals(tiles.at(tile_ids[t]), of_tile);
    for (std::size_t n = 0; n < ks.size(); ++n) residuals[ks[n]] = r[n];
  }
  for (std::size_t c = 0; c < points_S.size(); ++c) {
    const Eigen::Vector3d& origin = tiles.at(std::max(tile_of[c], -1L)).origin;
    Vector6d g;
    g << (points_S[c] - origin).cross(normals_S[c]), normals_S[c];
    sigma[c] = std::sqrt(std::max(0.0, g.dot(residuals[residual_of[c]] * g)));
  }
  return sigma;
}

}  // namespace uwscan::mapping
