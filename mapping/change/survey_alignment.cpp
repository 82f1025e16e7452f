#include "mapping/change/survey_alignment.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "perception/preprocessing/voxel_filter.hpp"
#include "perception/registration/icp.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/common/parallel_tasks.hpp"

namespace uwscan::mapping {
namespace {

using perception::PointCloud;
using Key = std::array<int, 3>;

constexpr double kMinGlobalFitness = 0.1;

// ICP stages' correspondence distances: at least one, each finite, > 0 and no larger than the
// one before.
void CheckStages(const OptionChecks& check, const std::vector<double>& stages, const char* name) {
  check.Require(!stages.empty(), name, "at least one stage", "none");
  for (std::size_t i = 0; i < stages.size(); ++i) {
    if (!(std::isfinite(stages[i]) && stages[i] > 0.0) || (i > 0 && stages[i] > stages[i - 1])) {
      check.Fail(std::string(name) + "[" + std::to_string(i) + "]",
                 "a finite value > 0 m, no larger than the stage before",
                 OptionValueText(stages[i]));
    }
  }
}

Key KeyOf(const Eigen::Vector3d& p, double tile_m) {
  return {static_cast<int>(std::floor(p.x() / tile_m)),
          static_cast<int>(std::floor(p.y() / tile_m)),
          static_cast<int>(std::floor(p.z() / tile_m))};
}

// The cloud about its own centroid: ICP's information is then taken about the tile, not about a
// point metres away where rotations and translations mix.
PointCloud Recentred(const PointCloud& cloud) {
  PointCloud out = cloud;
  const Eigen::Vector3d centroid = perception::Centroid(cloud);
  const Eigen::Vector3f shift = (centroid - cloud.origin).cast<float>();
  for (Eigen::Vector3f& p : out.points) p -= shift;
  out.origin = cloud.origin + shift.cast<double>();
  return out;
}

// sigma^2 times the pseudo-inverse of the information: directions without information get none.
Matrix6d CovarianceOf(const perception::RegistrationResult& r) {
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(r.information);
  const double largest = eigen.eigenvalues().maxCoeff();
  Eigen::Matrix<double, 6, 1> inverse = Eigen::Matrix<double, 6, 1>::Zero();
  for (int i = 0; i < 6; ++i) {
    if (eigen.eigenvalues()(i) > 1e-9 * largest) inverse(i) = 1.0 / eigen.eigenvalues()(i);
  }
  const double variance = r.inlier_plane_rmse * r.inlier_plane_rmse;
  return variance * eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
}

perception::IcpOptions PointToPlane(const std::vector<double>& stages) {
  perception::IcpOptions icp;
  icp.method = perception::IcpMethod::kPointToPlane;
  icp.max_correspondence_distance_m = stages;
  icp.max_iterations = 30 * static_cast<int>(stages.size());
  icp.max_iterations_per_stage = 30;
  icp.stall_iterations = 5;
  return icp;
}

// The reference's points within `margin_m` of a cloud's bounding box, about their centroid
// (empty below 3 points).
PointCloud ReferenceAround(const PointCloud& reference, const PointCloud& cloud, double margin_m) {
  Eigen::Vector3d lo = cloud.Point(0), hi = lo;
  for (std::size_t i = 1; i < cloud.size(); ++i) {
    lo = lo.cwiseMin(cloud.Point(i));
    hi = hi.cwiseMax(cloud.Point(i));
  }
  lo.array() -= margin_m;
  hi.array() += margin_m;
  std::vector<std::size_t> inside;
  for (std::size_t i = 0; i < reference.size(); ++i) {
    const Eigen::Vector3d q = reference.Point(i);
    if ((q.array() >= lo.array()).all() && (q.array() <= hi.array()).all()) inside.push_back(i);
  }
  return inside.size() < 3 ? PointCloud{} : Recentred(perception::Subset(reference, inside));
}

// The part of a tile's registration its surface pins firmly: the increment's components along
// the information's strong directions (eigenvalues above 1 % of the largest). A flat tile pins
// its height and tilt; what would slide it along the seabed is only the rim of a change, and
// sliding there would move the change instead of finding it.
Eigen::Isometry3d FirmPart(const perception::RegistrationResult& r, const Eigen::Vector3d& origin) {
  const Eigen::Matrix3d R = r.T_target_source.linear();
  const Eigen::AngleAxisd rotation(R);
  Eigen::Matrix<double, 6, 1> x;
  x << rotation.angle() * rotation.axis(), r.T_target_source * origin - origin;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(r.information);
  const double largest = eigen.eigenvalues().maxCoeff();
  Eigen::Matrix<double, 6, 1> firm = Eigen::Matrix<double, 6, 1>::Zero();
  for (int i = 0; i < 6; ++i) {
    const Eigen::Matrix<double, 6, 1> u = eigen.eigenvectors().col(i);
    if (eigen.eigenvalues()(i) > 0.01 * largest) firm += u * u.dot(x);
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const double angle = firm.head<3>().norm();
  if (angle > 0.0) T.linear() = Eigen::AngleAxisd(angle, firm.head<3>() / angle).toRotationMatrix();
  T.translation() = firm.tail<3>() + origin - T.linear() * origin;
  return T;
}

// The global transform as a prior of the tile's registration: directions its points leave free
// (a flat seabed's slides) stay where the whole map put them.
perception::IcpPrior TilePrior(const SurveyAlignmentOptions& options) {
  perception::IcpPrior prior;
  Eigen::Matrix<double, 6, 1> sigma;
  sigma << Eigen::Vector3d::Constant(options.tile_prior_rotation_rad),
      Eigen::Vector3d::Constant(options.tile_prior_translation_m);
  prior.information = sigma.cwiseInverse().cwiseAbs2().asDiagonal();
  prior.point_sigma_m = options.tile_point_sigma_m;
  return prior;
}

SurveyAlignment::Tile AlignTile(const PointCloud& source_W, const PointCloud& reference,
                                const Key& key, const SurveyAlignment& global,
                                const SurveyAlignmentOptions& options) {
  SurveyAlignment::Tile tile;
  tile.key = Eigen::Vector3i(key[0], key[1], key[2]);
  tile.T_reference_map = global.T_reference_map;
  const double reach_m = options.tile_max_correspondence_m.front();
  const PointCloud target = ReferenceAround(reference, source_W, reach_m);
  if (static_cast<int>(source_W.size()) < options.min_tile_points || target.size() < 3) return tile;
  perception::IcpOptions icp = PointToPlane(options.tile_max_correspondence_m);
  icp.prior = TilePrior(options);
  icp.threads = 1;  // the tiles run in parallel
  const perception::RegistrationResult r =
      perception::AlignIcp(source_W, target, Eigen::Isometry3d::Identity(), icp);
  // A tile the reference barely covers, or whose registration wandered beyond the first stage's
  // reach, keeps the global transform: a wrong local fit would show as a change over the tile.
  const double moved_m = (r.T_target_source * source_W.origin - source_W.origin).norm();
  if (r.fitness < 0.5 || !(moved_m < reach_m)) return tile;
  tile.T_reference_map = FirmPart(r, target.origin) * global.T_reference_map;
  tile.covariance = CovarianceOf(r);
  tile.origin_W = target.origin;
  tile.registered = true;
  return tile;
}

SurveyAlignment AlignGlobally(const PointCloud& source, const PointCloud& reference,
                              const SurveyAlignmentOptions& options) {
  SurveyAlignment alignment;
  const Eigen::Isometry3d start = options.T_reference_map.value_or(Eigen::Isometry3d::Identity());
  alignment.T_reference_map = start;
  if (options.T_reference_map) return alignment;
  const perception::RegistrationResult r = perception::AlignIcp(
      source, reference, start, PointToPlane(options.global_max_correspondence_m));
  if (r.fitness < kMinGlobalFitness) {
    throw Error("the map and the reference do not overlap: " +
                std::to_string(static_cast<int>(100.0 * r.fitness)) +
                " % of the map's points lie within " +
                std::to_string(options.global_max_correspondence_m.back()) +
                " m of the reference after registration (same world frame and units? give "
                "--transform or --reference-units)");
  }
  alignment.T_reference_map = r.T_target_source;
  alignment.global_fitness = r.fitness;
  alignment.global_rmse_m = r.inlier_plane_rmse;
  alignment.registered = true;
  return alignment;
}

}  // namespace

void SurveyAlignmentOptions::Check() const {
  const OptionChecks check("SurveyAlignmentOptions");
  CheckStages(check, global_max_correspondence_m, "global_max_correspondence_m");
  CheckStages(check, tile_max_correspondence_m, "tile_max_correspondence_m");
  check.NonNegative("tile_m", tile_m, "m");
  check.Positive("tile_prior_rotation_rad", tile_prior_rotation_rad, "rad");
  check.Positive("tile_prior_translation_m", tile_prior_translation_m, "m");
  check.Positive("tile_point_sigma_m", tile_point_sigma_m, "m");
  check.AtLeast("min_tile_points", min_tile_points, 3);
  check.Positive("tile_voxel_m", tile_voxel_m, "m");
  check.Positive("global_voxel_m", global_voxel_m, "m");
  check.Require(!T_reference_map || T_reference_map->matrix().allFinite(), "T_reference_map",
                "a finite transform");
}

const SurveyAlignment::Tile* SurveyAlignment::TileOf(const Eigen::Vector3d& p_map) const {
  if (tiles.empty()) return nullptr;
  const Key k = KeyOf(p_map, tile_m);
  const Eigen::Vector3i key(k[0], k[1], k[2]);
  const auto it = std::lower_bound(
      tiles.begin(), tiles.end(), key, [](const Tile& t, const Eigen::Vector3i& k) {
        return std::lexicographical_compare(t.key.data(), t.key.data() + 3, k.data(), k.data() + 3);
      });
  return it != tiles.end() && it->key == key ? &*it : nullptr;
}

namespace {

// A tile's share in placing a point (BlendedTiles).
struct TileWeight {
  const SurveyAlignment::Tile* tile;
  double weight;
};

// The existing tiles among the eight whose centres surround p_map, with trilinear weights
// renormalised to sum to 1 over them (empty when none of the eight exists).
std::vector<TileWeight> BlendedTiles(const SurveyAlignment& a, const Eigen::Vector3d& p_map) {
  std::vector<TileWeight> blend;
  if (a.tiles.empty()) return blend;
  const Eigen::Vector3d u = p_map / a.tile_m - Eigen::Vector3d::Constant(0.5);
  const Eigen::Vector3d base = u.array().floor();
  const Eigen::Vector3d f = u - base;
  double total = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    Eigen::Vector3d centre_m, weight;
    for (int axis = 0; axis < 3; ++axis) {
      const int step = (corner >> axis) & 1;
      centre_m(axis) = (base(axis) + step + 0.5) * a.tile_m;
      weight(axis) = step ? f(axis) : 1.0 - f(axis);
    }
    const double w = weight.prod();
    if (w <= 0.0) continue;
    if (const SurveyAlignment::Tile* tile = a.TileOf(centre_m)) {
      blend.push_back({tile, w});
      total += w;
    }
  }
  for (TileWeight& t : blend) t.weight /= total;
  return blend;
}

}  // namespace

Eigen::Vector3d SurveyAlignment::Place(const Eigen::Vector3d& p_map) const {
  const std::vector<TileWeight> blend = BlendedTiles(*this, p_map);
  if (blend.empty()) return T_reference_map * p_map;
  Eigen::Vector3d placed = Eigen::Vector3d::Zero();
  for (const TileWeight& t : blend) placed += t.weight * (t.tile->T_reference_map * p_map);
  return placed;
}

double SurveyAlignment::SigmaAlongNormal(const Eigen::Vector3d& p_map,
                                         const Eigen::Vector3d& q_reference,
                                         const Eigen::Vector3d& normal_W) const {
  double variance = 0.0;
  for (const TileWeight& t : BlendedTiles(*this, p_map)) {
    if (!t.tile->registered) continue;
    const Eigen::Vector3d lever = q_reference - t.tile->origin_W;
    Eigen::Matrix<double, 1, 6> j;
    j << lever.cross(normal_W).transpose(), normal_W.transpose();
    variance += t.weight * t.weight * std::max(0.0, (j * t.tile->covariance * j.transpose())(0));
  }
  return std::sqrt(variance);
}

SurveyAlignment AlignSurveys(const PointCloud& map, const PointCloud& reference,
                             const SurveyAlignmentOptions& options) {
  options.Check();
  const PointCloud source = perception::VoxelDownsample(map, {.leaf_m = options.tile_voxel_m});
  SurveyAlignment alignment = AlignGlobally(
      perception::VoxelDownsample(map, {.leaf_m = options.global_voxel_m}), reference, options);
  if (options.tile_m == 0.0) return alignment;
  alignment.tile_m = options.tile_m;
  std::map<Key, std::vector<std::size_t>> by_tile;
  for (std::size_t i = 0; i < source.size(); ++i)
    by_tile[KeyOf(source.Point(i), options.tile_m)].push_back(i);
  const std::vector<std::pair<Key, std::vector<std::size_t>>> tiles(by_tile.begin(), by_tile.end());
  alignment.tiles.resize(tiles.size());
  // Each tile's registration on one thread (its ICP's search too): they are independent.
  RunParallelTasks(std::ssize(tiles), 0, [&](std::ptrdiff_t t) {
    const auto& [key, indices] = tiles[static_cast<std::size_t>(t)];
    const PointCloud tile_W = Recentred(
        perception::Transformed(perception::Subset(source, indices), alignment.T_reference_map));
    alignment.tiles[static_cast<std::size_t>(t)] =
        AlignTile(tile_W, reference, key, alignment, options);
  });
  for (const SurveyAlignment::Tile& tile : alignment.tiles)
    if (!tile.registered) ++alignment.tiles_kept_global;
  return alignment;
}

}  // namespace uwscan::mapping
