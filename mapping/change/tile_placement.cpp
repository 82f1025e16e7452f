#include "mapping/change/tile_placement.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

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
// shares), and what the point-by-point variance needs of their joint covariance, with each pose's
// error [w, v] about its own position moved to a twist about the tile's `origin`:
// xi_i = [w, v + (t_i - origin) x w], so that every pose displaces a point p along n by
// g(p)^T xi_i with the same g(p) = [(p - origin) x n, n].
struct TilePoses {
  std::vector<std::size_t> poses;
  std::vector<double> weights;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::MatrixXd twists;            // Cov(xi), 6 per pose in `poses`' order
  std::vector<Matrix6d> with_tile;   // per pose i: sum_j w_j Cov(xi_i, xi_j)
  Matrix6d tile = Matrix6d::Zero();  // Cov of the tile's mean twist, sum_ij w_i w_j Cov(xi_i, xi_j)

  std::size_t Position(std::size_t pose) const {
    return static_cast<std::size_t>(std::lower_bound(poses.begin(), poses.end(), pose) -
                                    poses.begin());
  }

  // From the poses' joint covariance: the twists' and their sums against the tile's weights.
  void Prepare(const Survey& survey, const Eigen::MatrixXd& covariance) {
    const Eigen::Index m = std::ssize(poses);
    origin.setZero();
    for (const std::size_t pose : poses) origin += survey.poses[pose].translation();
    origin /= static_cast<double>(m);
    std::vector<Matrix6d> to_twist(poses.size(), Matrix6d::Identity());
    for (std::size_t i = 0; i < poses.size(); ++i)
      to_twist[i].block<3, 3>(3, 0) = Cross(survey.poses[poses[i]].translation() - origin);
    twists.resize(6 * m, 6 * m);
    for (Eigen::Index i = 0; i < m; ++i) {
      for (Eigen::Index j = 0; j < m; ++j) {
        twists.block<6, 6>(6 * i, 6 * j) = to_twist[static_cast<std::size_t>(i)] *
                                           covariance.block<6, 6>(6 * i, 6 * j) *
                                           to_twist[static_cast<std::size_t>(j)].transpose();
      }
    }
    with_tile.assign(poses.size(), Matrix6d::Zero());
    tile.setZero();
    for (Eigen::Index i = 0; i < m; ++i) {
      for (Eigen::Index j = 0; j < m; ++j)
        with_tile[static_cast<std::size_t>(i)] +=
            weights[static_cast<std::size_t>(j)] * twists.block<6, 6>(6 * i, 6 * j);
      tile += weights[static_cast<std::size_t>(i)] * with_tile[static_cast<std::size_t>(i)];
    }
  }

  // Cov(mean twist of the point's poses - the tile's mean twist).
  Matrix6d Residual(const SeenFrom& seen) const {
    Matrix6d own = Matrix6d::Zero(), cross = Matrix6d::Zero();
    for (const std::size_t a : seen.poses) {
      const Eigen::Index i = static_cast<Eigen::Index>(Position(a));
      cross += with_tile[static_cast<std::size_t>(i)];
      for (const std::size_t b : seen.poses)
        own += twists.block<6, 6>(6 * i, 6 * static_cast<Eigen::Index>(Position(b)));
    }
    return seen.share * seen.share * own - seen.share * (cross + cross.transpose()) + tile;
  }
};

std::map<long, TilePoses> PosesOfTiles(const std::vector<SeenFrom>& seen,
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
  }
  return tiles;
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
  std::map<long, TilePoses> tiles = PosesOfTiles(seen, tile_of);
  // Each tile's joint covariance: a sparse solve per column, the tiles in parallel.
  std::vector<TilePoses*> each;
  for (auto& [tile, t] : tiles) each.push_back(&t);
  std::vector<char> known(each.size(), 0);
#pragma omp parallel for schedule(dynamic, 1)
  for (std::size_t k = 0; k < each.size(); ++k) {
    const std::optional<Eigen::MatrixXd> covariance =
        survey.joint_uncertainty->Covariance(each[k]->poses);
    if (!covariance) continue;
    each[k]->Prepare(survey, *covariance);
    known[k] = 1;
  }
  if (std::find(known.begin(), known.end(), 0) != known.end()) return sigma;
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
  std::vector<Matrix6d> residuals(first_point.size());
#pragma omp parallel for schedule(dynamic, 16)
  for (std::size_t k = 0; k < first_point.size(); ++k) {
    const std::size_t c = first_point[k];
    residuals[k] = tiles.at(std::max(tile_of[c], -1L)).Residual(seen[c]);
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
