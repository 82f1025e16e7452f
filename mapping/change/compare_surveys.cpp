#include "mapping/change/compare_surveys.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>

#include "mapping/change/local_statistics.hpp"
#include "mapping/change/tile_placement.hpp"
#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/preprocessing/normals.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

using perception::PointCloud;

struct Box {
  Eigen::Vector3d lo, hi;
  double Diagonal() const { return (hi - lo).norm(); }
  std::string ToString() const {
    char text[160];
    std::snprintf(text, sizeof text, "[%.3g %.3g %.3g] .. [%.3g %.3g %.3g] m", lo.x(), lo.y(),
                  lo.z(), hi.x(), hi.y(), hi.z());
    return text;
  }
};

Box BoundsOf(const PointCloud& cloud, const Eigen::Isometry3d& T) {
  Box box{T * cloud.Point(0), T * cloud.Point(0)};
  for (std::size_t i = 1; i < cloud.size(); ++i) {
    const Eigen::Vector3d p = T * cloud.Point(i);
    box.lo = box.lo.cwiseMin(p);
    box.hi = box.hi.cwiseMax(p);
  }
  return box;
}

// Clouds in other units or frames are refused before any work, with what was seen.
void RequireComparable(const Survey& map, const Survey& reference,
                       const SurveyAlignmentOptions& options) {
  if (map.cloud.empty()) throw Error(map.name + ": the map has no points");
  if (reference.cloud.empty()) throw Error(reference.name + ": the reference has no points");
  const Box m =
      BoundsOf(map.cloud, options.T_reference_map.value_or(Eigen::Isometry3d::Identity()));
  const Box r = BoundsOf(reference.cloud, Eigen::Isometry3d::Identity());
  const double margin_m = options.global_max_correspondence_m.front();
  const bool meet =
      ((m.lo.array() - margin_m <= r.hi.array()) && (r.lo.array() - margin_m <= m.hi.array()))
          .all();
  const double ratio = r.Diagonal() / std::max(m.Diagonal(), 1e-9);
  std::string hint;
  if (ratio > 100.0)
    hint = " (the reference is " + std::to_string(static_cast<long>(ratio)) +
           " times larger: in millimetres? --reference-units mm)";
  if (!meet || ratio > 100.0) {
    throw Error(reference.name + ": the reference " + r.ToString() + " does not overlap the map " +
                m.ToString() + hint);
  }
}

perception::NormalOptions NormalsWithin(double radius_m) {
  perception::NormalOptions options;
  options.radius_m = radius_m;
  return options;
}

// The cloud with its normals, estimated where it has none (points without a plane around them
// dropped).
PointCloud WithNormals(const PointCloud& cloud, double radius_m) {
  if (cloud.has_normals()) return cloud;
  const perception::NormalsResult normals =
      perception::EstimateNormals(cloud, NormalsWithin(radius_m));
  return perception::AttachNormals(cloud, normals).cloud;
}

// Which way a core point's normal faces: as the reference's own normals where it has them
// (a design model's outside), else towards the nearest pose that saw the surface, else up (the
// world is NED).
class NormalOrientation {
 public:
  NormalOrientation(const Survey& reference, const Survey& map, const Eigen::Isometry3d& T_ref_map)
      : reference_(reference) {
    if (reference.cloud.has_normals()) {
      knn_ = std::make_unique<perception::KnnIndex>(reference.cloud.points);
      return;
    }
    for (const Eigen::Isometry3d& T : reference.poses) viewpoints_.push_back(T.translation());
    if (viewpoints_.empty()) {
      for (const Eigen::Isometry3d& T : map.poses)
        viewpoints_.push_back(T_ref_map * T.translation());
    }
  }

  Eigen::Vector3d operator()(const Eigen::Vector3d& p, const Eigen::Vector3d& n) const {
    return n.dot(Towards(p)) < 0.0 ? Eigen::Vector3d(-n) : n;
  }

 private:
  Eigen::Vector3d Towards(const Eigen::Vector3d& p) const {
    if (knn_) {
      std::vector<std::uint32_t> index;
      std::vector<float> d2;
      knn_->Query((p - reference_.cloud.origin).cast<float>(), 1, index, d2);
      return reference_.cloud.normals[index.front()].cast<double>();
    }
    if (viewpoints_.empty()) return -Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d* nearest = &viewpoints_.front();
    for (const Eigen::Vector3d& v : viewpoints_)
      if ((v - p).squaredNorm() < (*nearest - p).squaredNorm()) nearest = &v;
    return *nearest - p;
  }

  const Survey& reference_;
  std::unique_ptr<perception::KnnIndex> knn_;
  std::vector<Eigen::Vector3d> viewpoints_;
};

// A design model's core points whose outward normal faces away from the nearest of the map's
// poses: surfaces the sensor cannot have seen (back faces). Kept all when either lacks what the
// test needs.
std::vector<char> FacingTheSensor(const CorePoints& core, const Survey& reference,
                                  const Survey& map, const Eigen::Isometry3d& T_reference_map) {
  if (reference.kind != SurveyKind::kDesign || map.poses.empty()) return {};
  std::vector<Eigen::Vector3d> viewpoints;
  for (const Eigen::Isometry3d& T : map.poses)
    viewpoints.push_back(T_reference_map * T.translation());
  std::vector<char> visible(core.points_W.size(), 1);
  for (std::size_t i = 0; i < visible.size(); ++i) {
    const Eigen::Vector3d& p = core.points_W[i];
    const Eigen::Vector3d* nearest = &viewpoints.front();
    for (const Eigen::Vector3d& v : viewpoints)
      if ((v - p).squaredNorm() < (*nearest - p).squaredNorm()) nearest = &v;
    visible[i] = core.normals_W[i].dot(*nearest - p) > 0.0;
  }
  return visible;
}

// Each map point placed by the tiles around it (the global transform outside the tiles).
PointCloud AlignedMap(const PointCloud& map, const SurveyAlignment& alignment) {
  std::vector<Eigen::Vector3d> points(map.size());
  for (std::size_t i = 0; i < map.size(); ++i) points[i] = alignment.Place(map.Point(i));
  return perception::MakeCloud(points);
}

// The groups AddGroupSpread measures: per registration tile (one for the whole map without
// tiles), the surfaces facing up (within 30 degrees: seabed, tops) apart from the rest (flanks
// of pipes, walls, the sides of objects), which the surveys place less reproducibly, and the
// surface near an edge apart from the whole (AtSurfaceEdge).
std::vector<long> SpreadGroups(const SurveyComparison& c, const Eigen::Isometry3d& T_map_reference,
                               double edge_radius_m) {
  const std::vector<char> edge = AtSurfaceEdge(c.deviations, edge_radius_m);
  std::vector<long> group_of(c.deviations.size(), -1);
  for (std::size_t i = 0; i < c.deviations.size(); ++i) {
    const CoreDeviation& d = c.deviations[i];
    const SurveyAlignment::Tile* tile = c.alignment.TileOf(T_map_reference * d.point_W);
    const long tile_index = tile ? static_cast<long>(tile - c.alignment.tiles.data()) : -1;
    const bool up = -d.normal_W.z() > std::cos(M_PI / 6);  // NED: up is -z
    group_of[i] = 4 * (tile_index + 1) + 2 * edge[i] + (up ? 0 : 1);
  }
  return group_of;
}

// Each core point's registration tile (its index; -1 where the global transform placed it).
std::vector<long> TileIndices(const SurveyComparison& c, const Eigen::Isometry3d& T_map_reference) {
  std::vector<long> tile_of(c.deviations.size(), -1);
  for (std::size_t i = 0; i < c.deviations.size(); ++i) {
    const SurveyAlignment::Tile* tile =
        c.alignment.TileOf(T_map_reference * c.deviations[i].point_W);
    if (tile) tile_of[i] = static_cast<long>(tile - c.alignment.tiles.data());
  }
  return tile_of;
}

// Adds to each inspected core point's level of detection how loosely both surveys placed it
// against the rest of its tile (TileRelativePoseSigmas), where their joint pose covariances are
// known; the status follows.
void AddTileRelativePlacement(SurveyComparison& c, const Survey& map, const Survey& reference,
                              const Eigen::Isometry3d& T_map_reference, double seen_within_m,
                              double z) {
  if (!map.joint_uncertainty && !reference.joint_uncertainty) return;
  c.joint_pose_uncertainty_used = true;
  const std::vector<long> tile_of = TileIndices(c, T_map_reference);
  std::vector<Eigen::Vector3d> points_R, normals_R, points_M, normals_M;
  for (const CoreDeviation& d : c.deviations) {
    points_R.push_back(d.point_W);
    normals_R.push_back(d.normal_W);
    points_M.push_back(T_map_reference * d.point_W);
    normals_M.push_back(T_map_reference.linear() * d.normal_W);
  }
  const std::vector<double> sigma_map =
      TileRelativePoseSigmas(map, points_M, normals_M, tile_of, seen_within_m);
  const std::vector<double> sigma_reference =
      TileRelativePoseSigmas(reference, points_R, normals_R, tile_of, seen_within_m);
  for (std::size_t i = 0; i < c.deviations.size(); ++i) {
    CoreDeviation& d = c.deviations[i];
    if (d.status == SurfaceStatus::kNotInspected) continue;
    d.lod_m = z * std::sqrt(std::pow(d.lod_m / z, 2) + std::pow(sigma_map[i], 2) +
                            std::pow(sigma_reference[i], 2));
    d.status =
        std::abs(d.deviation_m) > d.lod_m ? SurfaceStatus::kChanged : SurfaceStatus::kUnchanged;
  }
}

SurfaceAreas AreasOf(const std::vector<CoreDeviation>& deviations, double spacing_m) {
  SurfaceAreas areas;
  const double cell_m2 = spacing_m * spacing_m;
  for (const CoreDeviation& d : deviations) {
    (d.status == SurfaceStatus::kChanged     ? areas.changed_m2
     : d.status == SurfaceStatus::kUnchanged ? areas.unchanged_m2
                                             : areas.not_inspected_m2) += cell_m2;
  }
  areas.core_points = static_cast<int>(deviations.size());
  return areas;
}

}  // namespace

void CompareOptions::Check() const {
  alignment.Check();
  deviation.Check();
  regions.Check();
  if (!(seen_within_m >= 0.0) || !std::isfinite(seen_within_m))
    throw Error("CompareOptions: seen_within_m must be finite and >= 0, got " +
                std::to_string(seen_within_m));
}

SurveyComparison CompareSurveys(const Survey& map, const Survey& reference,
                                const CompareOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  options.Check();
  RequireComparable(map, reference, options.alignment);
  SurveyComparison result;
  // The reference with normals: the registration's target, and what each cylinder averages
  // only the same surface's points of.
  const PointCloud target = WithNormals(reference.cloud, options.deviation.normal_radius_m);
  result.alignment = AlignSurveys(map.cloud, target, options.alignment);
  const PointCloud aligned =
      WithNormals(AlignedMap(map.cloud, result.alignment), options.deviation.normal_radius_m);

  DeviationOptions deviation = options.deviation;
  if (reference.kind == SurveyKind::kDesign) deviation.reference_point_sigma_m = 0.0;
  const NormalOrientation orient(reference, map, result.alignment.T_reference_map);
  CorePoints core = MakeCorePoints(reference.cloud, deviation, std::cref(orient));
  core.visible = FacingTheSensor(core, reference, map, result.alignment.T_reference_map);
  const Eigen::Isometry3d T_map_reference = result.alignment.T_reference_map.inverse();
  result.pose_covariances_used = result.alignment.tiles.empty();
  const auto placement_sigma = [&](const Eigen::Vector3d& c, const Eigen::Vector3d& n) {
    const Eigen::Vector3d p_map = T_map_reference * c;
    const double align = result.alignment.SigmaAlongNormal(p_map, c, n);
    if (!result.pose_covariances_used) return align;
    const double pose_map = PoseSigmaAlongNormal(map, p_map, T_map_reference.linear() * n);
    const double pose_reference = PoseSigmaAlongNormal(reference, c, n);
    return std::sqrt(align * align + pose_map * pose_map + pose_reference * pose_reference);
  };
  result.deviations = MeasureDeviations(aligned, target, core, deviation, placement_sigma);
  if (!result.pose_covariances_used && options.joint_pose_uncertainty) {
    AddTileRelativePlacement(result, map, reference, T_map_reference, options.seen_within_m,
                             TwoSidedQuantile(deviation.confidence));
  }
  if (deviation.local_offset_radius_m > 0.0) {
    RemoveLocalOffsets(result.deviations, deviation.local_offset_radius_m,
                       deviation.max_normal_angle_rad);
  }
  AddGroupSpread(result.deviations, SpreadGroups(result, T_map_reference, deviation.edge_radius_m),
                 TwoSidedQuantile(deviation.confidence));
  result.core_spacing_m = deviation.core_spacing_m;
  result.regions = FindChangeRegions(result.deviations, result.core_spacing_m, options.regions,
                                     result.region_of);
  result.areas = AreasOf(result.deviations, result.core_spacing_m);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace uwscan::mapping
