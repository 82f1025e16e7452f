#include "mapping/change/surface_deviation.hpp"

#include <omp.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <optional>

#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/preprocessing/voxel_filter.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

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
  // Each point comes as (u, v, t): across the line in the plane (e1, e2) and along it (n).
  void Projections(const Eigen::Vector3d& c_W, const Eigen::Vector3d& n, double min_cos,
                   std::vector<Eigen::Vector3d>& local, Scratch& s) const {
    local.clear();
    std::vector<std::uint32_t>& seen = s.seen;
    seen.clear();
    const int steps = static_cast<int>(std::ceil(half_length_m_ / radius_m_));
    const Eigen::Vector3d c = c_W - cloud_.origin;
    for (int k = -steps; k <= steps; ++k) {
      grid_.Query((c + (k * radius_m_) * n).cast<float>(), s.indices, s.d2);
      seen.insert(seen.end(), s.indices.begin(), s.indices.end());
    }
    std::sort(seen.begin(), seen.end());
    seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
    const Eigen::Vector3d e1 = n.unitOrthogonal(), e2 = n.cross(e1);
    for (std::uint32_t i : seen) {
      const Eigen::Vector3d d = cloud_.points[i].cast<double>() - c;
      const double along = d.dot(n);
      if (std::abs(along) > half_length_m_ || (d - along * n).squaredNorm() > radius_m_ * radius_m_)
        continue;
      if (cloud_.has_normals() && std::abs(cloud_.normals[i].cast<double>().dot(n)) < min_cos)
        continue;
      local.emplace_back(d.dot(e1), d.dot(e2), along);
    }
  }

 private:
  const PointCloud& cloud_;
  double radius_m_, half_length_m_;
  RadiusGrid grid_;
};

// Where a surface crosses the line, from the points of one cloud in the cylinder: the run of
// points along the line (split where consecutive ones are more than gap_m apart) nearest t = 0,
// fitted with a height function over the cross-section (a quadric from 12 points, a plane from
// 4, else their mean) so that a curved or sloping surface sampled unevenly (a pipe seen from one
// side) is not biased towards its denser side. Its value on the line is the surface's position;
// its variance follows from the fit's residuals (at least point_sigma_m per point).
struct SurfaceSample {
  double position_m = 0.0, variance_m2 = 0.0;
  int count = 0;
};

// The fit with `terms` terms (1 mean, 3 plane, 6 quadric); nullopt when the points do not
// surround the line well enough for it: the position's variance more than kMaxLeverage times
// what the same points would give it at the centre of their spread (an extrapolation).
constexpr double kMaxLeverage = 3.0;

std::optional<SurfaceSample> FitWith(std::span<const Eigen::Vector3d> run, int terms,
                                     double radius_m, double point_sigma_m) {
  const int n = static_cast<int>(run.size());
  if (n < terms) return std::nullopt;
  Eigen::MatrixXd a(n, terms);
  Eigen::VectorXd t(n);
  for (int i = 0; i < n; ++i) {
    const double u = run[static_cast<std::size_t>(i)].x() / radius_m;
    const double v = run[static_cast<std::size_t>(i)].y() / radius_m;
    const double row[6] = {1.0, u, v, u * u, u * v, v * v};
    for (int k = 0; k < terms; ++k) a(i, k) = row[k];
    t(i) = run[static_cast<std::size_t>(i)].z();
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(a.transpose() * a);
  const Eigen::VectorXd x = ldlt.solve(a.transpose() * t);
  const double leverage = ldlt.solve(Eigen::VectorXd::Unit(terms, 0))(0);
  if (ldlt.info() != Eigen::Success || !std::isfinite(x(0)) || !(leverage > 0.0) ||
      leverage * n > kMaxLeverage) {
    return std::nullopt;
  }
  const double rss = (a * x - t).squaredNorm();
  const double sigma2 =
      std::max(n > terms ? rss / (n - terms) : 0.0, point_sigma_m * point_sigma_m);
  return SurfaceSample{.position_m = x(0), .variance_m2 = sigma2 * leverage, .count = n};
}

// Points whose mean lies farther than this share of the radius from the line cover only a side
// of the cylinder's cross-section: a cloud's edge (the end of a swath, a shadow) passes through
// it. Over a half disc the mean lies 4 / (3 pi) = 0.42 radii off the line.
constexpr double kMaxMeanOffset = 0.5;

SurfaceSample FitSurface(std::span<const Eigen::Vector3d> run, double radius_m,
                         double point_sigma_m) {
  // The two clouds' surfaces are compared over the same footprint: where one covers only its
  // edge, its points are the swath's last, least reliable ones, and they speak for a patch they
  // did not see (measured: the change bench's false regions lay mostly along the maps' edges).
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector3d& p : run) mean += p.head<2>() / static_cast<double>(run.size());
  if (mean.norm() > kMaxMeanOffset * radius_m) return {};
  for (const int terms : {6, 3}) {
    if (static_cast<int>(run.size()) < 2 * terms) continue;
    if (const std::optional<SurfaceSample> fit = FitWith(run, terms, radius_m, point_sigma_m))
      return *fit;
  }
  return *FitWith(run, 1, radius_m, point_sigma_m);
}

SurfaceSample NearestSurface(std::vector<Eigen::Vector3d>& local, double gap_m, double radius_m,
                             double point_sigma_m) {
  std::sort(local.begin(), local.end(),
            [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a.z() < b.z(); });
  std::size_t best_begin = 0, best_end = 0;
  double best_distance = std::numeric_limits<double>::infinity();
  for (std::size_t begin = 0; begin < local.size();) {
    std::size_t end = begin + 1;
    double sum = local[begin].z();
    while (end < local.size() && local[end].z() - local[end - 1].z() <= gap_m)
      sum += local[end++].z();
    const double mean = sum / static_cast<double>(end - begin);
    if (std::abs(mean) < best_distance) {
      best_distance = std::abs(mean);
      best_begin = begin;
      best_end = end;
    }
    begin = end;
  }
  if (best_end == best_begin) return {};
  return FitSurface(std::span(local).subspan(best_begin, best_end - best_begin), radius_m,
                    point_sigma_m);
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
  const Eigen::Vector3d& l = eigen.eigenvalues();
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
  const OptionChecks check("DeviationOptions");
  check.Positive("core_spacing_m", core_spacing_m, "m");
  check.Positive("normal_radius_m", normal_radius_m, "m");
  check.Positive("cylinder_radius_m", cylinder_radius_m, "m");
  check.Positive("max_depth_m", max_depth_m, "m");
  check.Positive("surface_gap_m", surface_gap_m, "m");
  check.NonNegative("local_offset_radius_m", local_offset_radius_m, "m");
  check.Positive("edge_radius_m", edge_radius_m, "m");
  check.AtLeast("min_points", min_points, 2);
  check.NonNegative("map_point_sigma_m", map_point_sigma_m, "m");
  check.NonNegative("reference_point_sigma_m", reference_point_sigma_m, "m");
  check.InRange("confidence", confidence, 0.0, 1.0, Interval::kOpen);
  check.Require(max_normal_angle_rad >= 0.0 && max_normal_angle_rad <= M_PI / 2,
                "max_normal_angle_rad", "in [0, pi/2] rad", max_normal_angle_rad);
  check.AtLeast("threads", threads, 0);
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
  const PointCloud voxels =
      SpacedOut(perception::VoxelDownsample(reference, {.leaf_m = options.core_spacing_m}),
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
    std::vector<Eigen::Vector3d> local;
    CylinderSearch::Scratch scratch;
#pragma omp for schedule(dynamic, 256)
    for (std::size_t i = 0; i < out.size(); ++i) {
      CoreDeviation& d = out[i];
      d.point_W = core.points_W[i];
      d.normal_W = core.normals_W[i];
      if (!core.visible.empty() && !core.visible[i]) continue;
      in_reference.Projections(d.point_W, d.normal_W, min_cos, local, scratch);
      const SurfaceSample r = NearestSurface(
          local, options.surface_gap_m, options.cylinder_radius_m, options.reference_point_sigma_m);
      in_map.Projections(d.point_W, d.normal_W, min_cos, local, scratch);
      const SurfaceSample m = NearestSurface(local, options.surface_gap_m,
                                             options.cylinder_radius_m, options.map_point_sigma_m);
      d.map_points = m.count;
      d.reference_points = r.count;
      if (m.count < options.min_points || r.count < 1) continue;
      const double placement = placement_sigma(d.point_W, d.normal_W);
      d.deviation_m = m.position_m - r.position_m;
      d.lod_m = z * std::sqrt(m.variance_m2 + r.variance_m2 + placement * placement);
      d.status =
          std::abs(d.deviation_m) > d.lod_m ? SurfaceStatus::kChanged : SurfaceStatus::kUnchanged;
    }
  }
  return out;
}

}  // namespace uwscan::mapping
