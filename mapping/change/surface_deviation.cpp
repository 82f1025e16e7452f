#include "mapping/change/surface_deviation.hpp"

#include <omp.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/preprocessing/voxel_filter.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

using perception::PointCloud;
using perception::RadiusGrid;

// Points of a cloud near a line, found with sphere queries spaced along it.
class CylinderSearch {
 public:
  CylinderSearch(const PointCloud& cloud, double radius_m, double half_length_m)
      : cloud_(cloud),
        radius_m_(radius_m),
        half_length_m_(half_length_m),
        // A sphere of this radius covers the cylinder's slice of one radius's length around it.
        grid_(cloud.points, radius_m * 1.12) {}

  // Scratch space of one thread's searches.
  struct Scratch {
    std::vector<std::uint32_t> indices, seen;
    std::vector<float> d2;
  };

  // Each point within radius_m of the line c + t n, |t| <= half_length_m, as its t (metres).
  // Points whose normal (where the cloud has normals) is more than acos(min_cos) off the line's
  // direction, either way, are left out: they lie on another surface that crosses the cylinder.
  void Projections(const Eigen::Vector3d& c_W, const Eigen::Vector3d& n, double min_cos,
                   std::vector<double>& t, Scratch& s) const {
    t.clear();
    std::vector<std::uint32_t>& seen = s.seen;
    std::vector<std::uint32_t>& indices = s.indices;
    std::vector<float>& d2 = s.d2;
    seen.clear();
    const int steps = static_cast<int>(std::ceil(half_length_m_ / radius_m_));
    const Eigen::Vector3d c = c_W - cloud_.origin;
    for (int k = -steps; k <= steps; ++k) {
      grid_.Query((c + (k * radius_m_) * n).cast<float>(), indices, d2);
      seen.insert(seen.end(), indices.begin(), indices.end());
    }
    std::sort(seen.begin(), seen.end());
    seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
    for (std::uint32_t i : seen) {
      const Eigen::Vector3d d = cloud_.points[i].cast<double>() - c;
      const double along = d.dot(n);
      if (std::abs(along) > half_length_m_ || (d - along * n).squaredNorm() > radius_m_ * radius_m_)
        continue;
      if (cloud_.has_normals() && std::abs(cloud_.normals[i].cast<double>().dot(n)) < min_cos)
        continue;
      t.push_back(along);
    }
  }

 private:
  const PointCloud& cloud_;
  double radius_m_, half_length_m_;
  RadiusGrid grid_;
};

// Mean, spread and count of the surface nearest t = 0 among sorted projections: runs of values
// split where consecutive ones are more than `gap_m` apart.
struct SurfaceSample {
  double mean_m = 0.0, variance_m2 = 0.0;
  int count = 0;
};
SurfaceSample NearestSurface(std::vector<double>& t, double gap_m) {
  std::sort(t.begin(), t.end());
  SurfaceSample best;
  double best_distance = std::numeric_limits<double>::infinity();
  for (std::size_t begin = 0; begin < t.size();) {
    std::size_t end = begin + 1;
    while (end < t.size() && t[end] - t[end - 1] <= gap_m) ++end;
    double sum = 0.0;
    for (std::size_t i = begin; i < end; ++i) sum += t[i];
    const double mean = sum / static_cast<double>(end - begin);
    if (std::abs(mean) < best_distance) {
      best_distance = std::abs(mean);
      double squares = 0.0;
      for (std::size_t i = begin; i < end; ++i) squares += (t[i] - mean) * (t[i] - mean);
      best = {.mean_m = mean,
              .variance_m2 = end - begin > 1 ? squares / static_cast<double>(end - begin - 1) : 0.0,
              .count = static_cast<int>(end - begin)};
    }
    begin = end;
  }
  return best;
}

// The unit normal of the points around c (their covariance's least eigenvector); zero when they
// do not define a plane.
Eigen::Vector3d PlaneNormal(const PointCloud& cloud, const Eigen::Vector3d& c_W,
                            std::span<const std::uint32_t> indices) {
  if (indices.size() < 3) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d c = c_W - cloud.origin;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (std::uint32_t i : indices) {
    const Eigen::Vector3d d = cloud.points[i].cast<double>() - c;
    covariance += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  const Eigen::Vector3d l = eigen.eigenvalues();
  if (!(l(1) > 1e-6 * l(2))) return Eigen::Vector3d::Zero();  // collinear
  return eigen.eigenvectors().col(0).normalized();
}

// The points with those closer than min_distance_m to an earlier one dropped. A surface lying
// along a voxel boundary (a seabed at 10.000 m, voxels of 1 cm) leaves a centroid in the voxels
// either side, a fraction of a millimetre apart: core points must sample area evenly.
PointCloud SpacedOut(const PointCloud& cloud, double min_distance_m) {
  const RadiusGrid grid(cloud.points, min_distance_m);
  std::vector<char> dropped(cloud.size(), 0);
  std::vector<std::size_t> kept;
  std::vector<std::uint32_t> indices;
  std::vector<float> d2;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (dropped[i]) continue;
    kept.push_back(i);
    grid.Query(cloud.points[i], indices, d2);
    for (std::uint32_t j : indices)
      if (j > i) dropped[j] = 1;
  }
  return perception::Subset(cloud, kept);
}

int Threads(int threads) { return threads > 0 ? threads : omp_get_max_threads(); }

}  // namespace

void DeviationOptions::Check() const {
  const auto positive = [](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v))
      throw Error(std::string("DeviationOptions: ") + name + " must be finite and > 0");
  };
  positive(core_spacing_m, "core_spacing_m");
  positive(normal_radius_m, "normal_radius_m");
  positive(cylinder_radius_m, "cylinder_radius_m");
  positive(max_depth_m, "max_depth_m");
  positive(surface_gap_m, "surface_gap_m");
  if (!(local_offset_radius_m >= 0.0) || !std::isfinite(local_offset_radius_m))
    throw Error("DeviationOptions: local_offset_radius_m must be finite and >= 0");
  if (min_points < 2) throw Error("DeviationOptions: min_points must be >= 2");
  if (!(map_point_sigma_m >= 0.0) || !(reference_point_sigma_m >= 0.0) ||
      !std::isfinite(map_point_sigma_m) || !std::isfinite(reference_point_sigma_m))
    throw Error("DeviationOptions: the point sigmas must be finite and >= 0");
  if (!(confidence > 0.0 && confidence < 1.0))
    throw Error("DeviationOptions: confidence must be in (0, 1)");
  if (!(max_normal_angle_rad >= 0.0 && max_normal_angle_rad <= M_PI / 2))
    throw Error("DeviationOptions: max_normal_angle_rad must be in [0, pi/2]");
  if (threads < 0) throw Error("DeviationOptions: threads must be >= 0");
}

double TwoSidedQuantile(double confidence) {
  if (!(confidence > 0.0 && confidence < 1.0))
    throw Error("TwoSidedQuantile: confidence must be in (0, 1)");
  // P(|N| <= z) = erf(z / sqrt 2) rises monotonically: bisection to double precision.
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::erf(mid / std::sqrt(2.0)) < confidence ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

CorePoints MakeCorePoints(
    const PointCloud& reference, const DeviationOptions& options,
    const std::function<Eigen::Vector3d(const Eigen::Vector3d&, const Eigen::Vector3d&)>& orient) {
  options.Check();
  if (reference.empty()) throw Error("the reference has no points");
  const PointCloud voxels = SpacedOut(
      perception::VoxelDownsample(reference, {.leaf_m = options.core_spacing_m}),
      0.5 * options.core_spacing_m);
  const RadiusGrid grid(reference.points, options.normal_radius_m);
  std::vector<Eigen::Vector3d> normals(voxels.size(), Eigen::Vector3d::Zero());
#pragma omp parallel num_threads(Threads(options.threads))
  {
    std::vector<std::uint32_t> indices;
    std::vector<float> d2;
#pragma omp for schedule(static)
    for (std::size_t i = 0; i < voxels.size(); ++i) {
      const Eigen::Vector3d p = voxels.Point(i);
      grid.Query((p - reference.origin).cast<float>(), indices, d2);
      const Eigen::Vector3d n = PlaneNormal(reference, p, indices);
      if (n.squaredNorm() > 0.0) normals[i] = orient(p, n);
    }
  }
  CorePoints core;
  for (std::size_t i = 0; i < voxels.size(); ++i) {
    if (normals[i].squaredNorm() == 0.0) continue;
    core.points_W.push_back(voxels.Point(i));
    core.normals_W.push_back(normals[i]);
  }
  return core;
}

std::vector<CoreDeviation> MeasureDeviations(
    const PointCloud& map, const PointCloud& reference, const CorePoints& core,
    const DeviationOptions& options,
    const std::function<double(const Eigen::Vector3d&, const Eigen::Vector3d&)>& placement_sigma) {
  options.Check();
  if (map.empty()) throw Error("the map has no points");
  if (reference.empty()) throw Error("the reference has no points");
  const double z = TwoSidedQuantile(options.confidence);
  const double min_cos = std::cos(options.max_normal_angle_rad);
  std::vector<CoreDeviation> out(core.points_W.size());
  const CylinderSearch in_map(map, options.cylinder_radius_m, options.max_depth_m);
  const CylinderSearch in_reference(reference, options.cylinder_radius_m, options.max_depth_m);
#pragma omp parallel num_threads(Threads(options.threads))
  {
    std::vector<double> t;
    CylinderSearch::Scratch scratch;
#pragma omp for schedule(dynamic, 256)
    for (std::size_t i = 0; i < out.size(); ++i) {
      CoreDeviation& d = out[i];
      d.point_W = core.points_W[i];
      d.normal_W = core.normals_W[i];
      if (!core.visible.empty() && !core.visible[i]) continue;
      in_reference.Projections(d.point_W, d.normal_W, min_cos, t, scratch);
      const SurfaceSample r = NearestSurface(t, options.surface_gap_m);
      in_map.Projections(d.point_W, d.normal_W, min_cos, t, scratch);
      const SurfaceSample m = NearestSurface(t, options.surface_gap_m);
      d.map_points = m.count;
      d.reference_points = r.count;
      if (m.count < options.min_points || r.count < 1) continue;
      const double map_var = std::max(m.variance_m2, options.map_point_sigma_m * options.map_point_sigma_m);
      const double ref_var = std::max(r.variance_m2, options.reference_point_sigma_m *
                                                          options.reference_point_sigma_m);
      const double placement = placement_sigma(d.point_W, d.normal_W);
      const double variance = map_var / m.count + ref_var / r.count + placement * placement;
      d.deviation_m = m.mean_m - r.mean_m;
      d.lod_m = z * std::sqrt(variance);
      d.status = std::abs(d.deviation_m) > d.lod_m ? SurfaceStatus::kChanged : SurfaceStatus::kUnchanged;
    }
  }
  return out;
}

}  // namespace uwscan::mapping

namespace uwscan::mapping {

void RemoveLocalOffsets(std::vector<CoreDeviation>& deviations, double radius_m,
                        double max_normal_angle_rad) {
  if (!(radius_m > 0.0)) throw Error("RemoveLocalOffsets: radius_m must be > 0");
  std::vector<std::size_t> inspected;
  for (std::size_t i = 0; i < deviations.size(); ++i)
    if (deviations[i].status != SurfaceStatus::kNotInspected) inspected.push_back(i);
  if (inspected.empty()) return;
  const Eigen::Vector3d origin = deviations[inspected.front()].point_W;
  std::vector<Eigen::Vector3f> points;
  for (std::size_t i : inspected) points.push_back((deviations[i].point_W - origin).cast<float>());
  const RadiusGrid grid(points, radius_m);
  const double min_cos = std::cos(max_normal_angle_rad);
  constexpr std::size_t kMaxSamples = 256;  // the median of a window from this many, evenly strided
  std::vector<double> offsets(inspected.size(), 0.0);
#pragma omp parallel
  {
    std::vector<std::uint32_t> neighbours;
    std::vector<float> d2;
    std::vector<double> values;
#pragma omp for schedule(dynamic, 256)
    for (std::size_t k = 0; k < inspected.size(); ++k) {
      const CoreDeviation& d = deviations[inspected[k]];
      grid.Query(points[k], neighbours, d2);
      std::sort(neighbours.begin(), neighbours.end());
      const std::size_t stride = std::max<std::size_t>(1, neighbours.size() / kMaxSamples);
      values.clear();
      for (std::size_t j = 0; j < neighbours.size(); j += stride) {
        const CoreDeviation& n = deviations[inspected[neighbours[j]]];
        if (n.normal_W.dot(d.normal_W) >= min_cos) values.push_back(n.deviation_m);
      }
      if (values.empty()) continue;
      const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
      std::nth_element(values.begin(), middle, values.end());
      offsets[k] = *middle;
    }
  }
  for (std::size_t k = 0; k < inspected.size(); ++k) deviations[inspected[k]].deviation_m -= offsets[k];
}

}  // namespace uwscan::mapping
