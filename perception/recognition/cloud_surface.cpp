#include "perception/recognition/cloud_surface.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <vector>

#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/cloud/cloud_scale.hpp"
#include "perception/preprocessing/normals.hpp"
#include "perception/preprocessing/voxel_filter.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/sim/ray_caster.hpp"
#include "scanner/sim/virtual_scanner.hpp"

namespace uwscan::perception {
namespace {

constexpr std::size_t kMinPoints = 20;
constexpr int kDiscSides = 6;
constexpr double kMaxThinningSteps = 500.0;
constexpr int kAgreeingNeighbours = 8;  // voxels along the bounding box's diagonal, at most
// Lines of sight closer than this to a disc's plane (cosine) are not tried: a neighbour's disc,
// tilted by the surface's curvature, would block them on either side.
constexpr double kMinSightCosine = 0.3;

// The points with unit normals (any sign), those without a valid normal dropped.
struct Oriented {
  std::vector<Eigen::Vector3d> points, normals;
};

Oriented PointsWithNormals(const PointCloud& cloud, const CloudSurfaceOptions& options) {
  VoxelFilterOptions thin;
  // A large object keeps at most a few hundred thousand discs.
  thin.leaf_m = std::max(options.thinning_m, BoundingBoxDiagonal(cloud) / kMaxThinningSteps);
  const PointCloud thinned = VoxelDownsample(cloud, thin);
  NormalOptions normal_options;
  normal_options.k = options.normal_neighbours;
  normal_options.viewpoint = Centroid(thinned);
  normal_options.threads = options.threads;
  const CloudWithNormals with = AttachNormals(thinned, EstimateNormals(thinned, normal_options));
  Oriented o;
  for (std::size_t i = 0; i < with.cloud.size(); ++i) {
    o.points.push_back(with.cloud.Point(i));
    // Facing away from the centroid: the guess a disc keeps when its lines of sight leave
    // equally on both sides (an open sheet).
    o.normals.push_back(-with.cloud.normals[i].cast<double>().normalized());
  }
  return o;
}

// A disc of `radius_m` about p in the plane normal to n, wound counter-clockwise seen from +n.
void AddDisc(const Eigen::Vector3d& p, const Eigen::Vector3d& n, double radius_m,
             scanner::TriangleMesh& mesh) {
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  const int centre = static_cast<int>(mesh.vertices.size());
  mesh.vertices.push_back(p);
  for (int k = 0; k < kDiscSides; ++k) {
    const double a = 2.0 * std::numbers::pi * k / kDiscSides;
    mesh.vertices.push_back(p + radius_m * (std::cos(a) * u + std::sin(a) * v));
  }
  for (int k = 0; k < kDiscSides; ++k) {
    mesh.triangles.emplace_back(centre, centre + 1 + k, centre + 1 + (k + 1) % kDiscSides);
  }
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

scanner::TriangleMesh Discs(const Oriented& o, double radius_m) {
  scanner::TriangleMesh mesh;
  for (std::size_t i = 0; i < o.points.size(); ++i)
    AddDisc(o.points[i], o.normals[i], radius_m, mesh);
  return mesh;
}

// Flips each normal towards the more open side of its disc: the one where lines of sight run
// farther before they meet another disc, by the median (those that leave the object count as
// running `reach`; a few that slip through gaps between discs do not decide).
// Outside a closed object most leave; in a pipe's bore none leaves either side, but the bore is
// wide open to one side and the wall's thickness to the other. (Triangles are two-sided to the
// caster, so the first guess's signs do not matter.)
void FaceOutwards(Oriented& o, double radius_m, const CloudSurfaceOptions& options) {
  scanner::sim::SceneObject surface;
  surface.shape = scanner::sim::ObjectShape::kMesh;
  surface.mesh = Discs(o, radius_m);
  const scanner::sim::RayCaster caster({surface});
  const std::vector<Eigen::Vector3d> sights = scanner::sim::SphereDirections(options.directions);
  const double reach = 2.0 * surface.mesh.BoundingBoxDiagonal();
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 64) num_threads(threads)
  for (std::size_t i = 0; i < o.points.size(); ++i) {
    std::vector<double> front, back;
    for (const Eigen::Vector3d& d : sights) {
      const double c = d.dot(o.normals[i]);
      if (std::abs(c) < kMinSightCosine) continue;
      const std::optional<scanner::sim::SurfaceHit> hit =
          caster.Cast({o.points[i], d}, 0.5 * radius_m, reach);
      (c > 0.0 ? front : back).push_back(hit ? hit->distance_m : reach);
    }
    if (Median(back) > Median(front)) o.normals[i] = -o.normals[i];
  }
}

// Each disc then turns to agree with most of its nearest neighbours, twice over: a surface is
// oriented as a whole, and the few lines of sight a single disc casts leave some discs wrong.
void AgreeWithNeighbours(Oriented& o) {
  std::vector<Eigen::Vector3f> points;
  for (const Eigen::Vector3d& p : o.points) points.push_back(p.cast<float>());
  const KnnIndex index(points);
  std::vector<std::vector<std::uint32_t>> neighbours(o.points.size());
  std::vector<float> squared;
  for (std::size_t i = 0; i < o.points.size(); ++i) {
    index.Query(points[i], kAgreeingNeighbours + 1, neighbours[i], squared);
  }
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<Eigen::Vector3d> agreed = o.normals;
    for (std::size_t i = 0; i < o.points.size(); ++i) {
      int votes = 0;
      for (std::uint32_t j : neighbours[i]) {
        if (j == i) continue;
        votes += o.normals[i].dot(o.normals[j]) >= 0.0 ? 1 : -1;
      }
      if (votes < 0) agreed[i] = -o.normals[i];
    }
    o.normals = std::move(agreed);
  }
}

}  // namespace

void CloudSurfaceOptions::Check() const {
  const OptionChecks check("CloudSurfaceOptions");
  check.Positive("thinning_m", thinning_m, "m");
  check.Positive("disc_radius_spacings", disc_radius_spacings, "");
  check.AtLeast("normal_neighbours", normal_neighbours, 3);
  check.AtLeast("directions", directions, 8);
  check.AtLeast("threads", threads, 0);
}

scanner::TriangleMesh CloudSurface(const PointCloud& cloud_m, const CloudSurfaceOptions& options) {
  options.Check();
  RequireValidCloud(cloud_m, "CloudSurface: the scan", kMinPoints);
  Oriented o = PointsWithNormals(cloud_m, options);
  if (o.points.size() < kMinPoints) {
    throw Error("CloudSurface: only " + std::to_string(o.points.size()) +
                " points of the scan have a surface normal (at least " +
                std::to_string(kMinPoints) + ")");
  }
  const double spacing_m = MedianPointSpacing(MakeCloud(o.points));
  const double radius_m = options.disc_radius_spacings * spacing_m;
  if (!(radius_m > 0.0)) throw Error("CloudSurface: the scan's points all coincide");
  FaceOutwards(o, radius_m, options);
  AgreeWithNeighbours(o);
  return Discs(o, radius_m);
}

}  // namespace uwscan::perception
