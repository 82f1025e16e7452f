#include "perception/preprocessing/normals.hpp"

#include <omp.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>

#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/preprocessing/knn_grid.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::perception {
namespace {

constexpr double kMinPlanarity = 1e-6;  // l1 / l2 below this: the neighbourhood is a line

struct PlaneEstimate {
  Eigen::Vector3d normal;
  double curvature;
};

// PCA of the neighbourhood; offsets are taken about the query point before averaging.
std::optional<PlaneEstimate> FitNeighbourhood(const std::vector<Eigen::Vector3f>& points,
                                              const Eigen::Vector3f& query,
                                              std::span<const std::uint32_t> neighbours) {
  if (neighbours.size() < 3) return std::nullopt;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum_sq = Eigen::Matrix3d::Zero();
  for (std::uint32_t j : neighbours) {
    const Eigen::Vector3d d = (points[j] - query).cast<double>();
    sum += d;
    sum_sq.noalias() += d * d.transpose();
  }
  const double count = static_cast<double>(neighbours.size());
  const Eigen::Vector3d mean = sum / count;
  const Eigen::Matrix3d covariance = sum_sq / count - mean * mean.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  const Eigen::Vector3d l = solver.eigenvalues().cwiseMax(0.0);  // ascending
  if (!(l[2] > 0.0) || l[1] <= kMinPlanarity * l[2]) return std::nullopt;
  return PlaneEstimate{solver.eigenvectors().col(0).normalized(), l[0] / l.sum()};
}

}  // namespace

void NormalOptions::Check() const {
  const OptionChecks check("NormalOptions");
  check.NonNegative("radius_m", radius_m, "m");
  check.NonNegative("knn_cell_m", knn_cell_m, "m");
  if (radius_m == 0.0) check.AtLeast("k", k, 3, "(a plane needs 3 points)");
  check.Require(viewpoint.allFinite(), "viewpoint", "finite coordinates");
  check.AtLeast("threads", threads, 0);
}

NormalsResult EstimateNormals(const PointCloud& cloud, const NormalOptions& options) {
  options.Check();
  RequireValidCloud(cloud, "EstimateNormals: input cloud", 0);
  const std::size_t n = cloud.size();
  NormalsResult result;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  result.normals.assign(n, Eigen::Vector3f::Constant(nan));
  result.curvatures.assign(n, nan);
  if (n == 0) return result;

  // The viewpoint relative to the cloud's origin, in double.
  const Eigen::Vector3d viewpoint = options.viewpoint - cloud.origin;
  auto fit = [&](std::size_t i, std::span<const std::uint32_t> neighbours) {
    const std::optional<PlaneEstimate> plane =
        FitNeighbourhood(cloud.points, cloud.points[i], neighbours);
    if (!plane) return;
    Eigen::Vector3d normal = plane->normal;
    if (normal.dot(viewpoint - cloud.points[i].cast<double>()) < 0.0) normal = -normal;
    result.normals[i] = normal.cast<float>();
    result.curvatures[i] = static_cast<float>(plane->curvature);
  };
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  if (options.radius_m == 0.0 && options.knn_cell_m > 0.0) {
    KnnGrid(cloud.points, options.knn_cell_m).ForEachPoint(options.k, threads, fit);
  } else {
    std::optional<RadiusGrid> grid;
    std::optional<KnnIndex> knn;
    if (options.radius_m > 0.0) {
      grid.emplace(cloud.points, options.radius_m);
    } else {
      knn.emplace(cloud.points);
    }
#pragma omp parallel num_threads(threads)
    {
      std::vector<std::uint32_t> neighbours;
      std::vector<float> d2;
#pragma omp for schedule(dynamic, 256)
      for (std::ptrdiff_t signed_i = 0; signed_i < static_cast<std::ptrdiff_t>(n); ++signed_i) {
        const std::size_t i = static_cast<std::size_t>(signed_i);
        if (grid) {
          grid->Query(cloud.points[i], neighbours, d2);
        } else {
          knn->Query(cloud.points[i], options.k, neighbours, d2);
        }
        fit(i, neighbours);
      }
    }
  }
  for (const Eigen::Vector3f& normal : result.normals) {
    if (!normal.allFinite()) ++result.num_invalid;
  }
  return result;
}

CloudWithNormals AttachNormals(const PointCloud& cloud, const NormalsResult& normals) {
  if (normals.normals.size() != cloud.size() || normals.curvatures.size() != cloud.size()) {
    throw Error("AttachNormals: " + std::to_string(normals.normals.size()) + " normals and " +
                std::to_string(normals.curvatures.size()) + " curvatures for a cloud of " +
                std::to_string(cloud.size()) + " points");
  }
  CloudWithNormals out;
  out.cloud.origin = cloud.origin;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!normals.normals[i].allFinite() || !std::isfinite(normals.curvatures[i])) continue;
    out.cloud.points.push_back(cloud.points[i]);
    out.cloud.normals.push_back(normals.normals[i]);
    out.curvatures.push_back(normals.curvatures[i]);
    out.source_indices.push_back(i);
  }
  return out;
}

}  // namespace uwscan::perception
