#include "mapping/change/change_regions.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "perception/cloud/cloud_neighbors.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::mapping {
namespace {

// Connected groups of the significant points of one sign (breadth-first over a radius grid).
std::vector<std::vector<std::size_t>> ConnectedGroups(const std::vector<CoreDeviation>& d,
                                                      double link_m) {
  std::vector<std::size_t> changed;
  for (std::size_t i = 0; i < d.size(); ++i)
    if (d[i].status == SurfaceStatus::kChanged) changed.push_back(i);
  if (changed.empty()) return {};
  const Eigen::Vector3d origin = d[changed.front()].point_W;
  std::vector<Eigen::Vector3f> points;
  for (std::size_t i : changed) points.push_back((d[i].point_W - origin).cast<float>());
  const perception::RadiusGrid grid(points, link_m);
  std::vector<char> visited(changed.size(), 0);
  std::vector<std::vector<std::size_t>> groups;
  std::vector<std::uint32_t> neighbours;
  std::vector<float> d2;
  for (std::size_t seed = 0; seed < changed.size(); ++seed) {
    if (visited[seed]) continue;
    const bool gained = d[changed[seed]].deviation_m > 0.0;
    std::vector<std::size_t> group, queue = {seed};
    visited[seed] = 1;
    while (!queue.empty()) {
      const std::size_t k = queue.back();
      queue.pop_back();
      group.push_back(changed[k]);
      grid.Query(points[k], neighbours, d2);
      for (std::uint32_t j : neighbours) {
        if (visited[j] || (d[changed[j]].deviation_m > 0.0) != gained) continue;
        visited[j] = 1;
        queue.push_back(j);
      }
    }
    std::sort(group.begin(), group.end());
    groups.push_back(std::move(group));
  }
  return groups;
}

ChangeRegion Describe(const std::vector<CoreDeviation>& d, std::vector<std::size_t> indices,
                      double cell_m2) {
  ChangeRegion r;
  r.core_indices = std::move(indices);
  const double n = static_cast<double>(r.core_indices.size());
  double lod_sum = 0.0, abs_sum = 0.0;
  for (std::size_t i : r.core_indices) {
    r.centroid_W += d[i].point_W / n;
    r.mean_deviation_m += d[i].deviation_m / n;
    if (std::abs(d[i].deviation_m) > std::abs(r.extreme_deviation_m))
      r.extreme_deviation_m = d[i].deviation_m;
    r.volume_m3 += d[i].deviation_m * cell_m2;
    lod_sum += d[i].lod_m;
    abs_sum += std::abs(d[i].deviation_m);
  }
  r.area_m2 = n * cell_m2;
  r.significance = lod_sum > 0.0 ? abs_sum / lod_sum : 0.0;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (std::size_t i : r.core_indices) {
    const Eigen::Vector3d e = d[i].point_W - r.centroid_W;
    covariance += e * e.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (std::size_t i : r.core_indices) {
    const Eigen::Vector3d local = eigen.eigenvectors().transpose() * (d[i].point_W - r.centroid_W);
    lo = lo.cwiseMin(local);
    hi = hi.cwiseMax(local);
  }
  // One core spacing added: a single point covers one cell. Largest axis first.
  const double cell_m = std::sqrt(cell_m2);
  r.extent_m = (hi - lo).reverse() + Eigen::Vector3d::Constant(cell_m);
  return r;
}

}  // namespace

void RegionOptions::Check() const {
  const OptionChecks check("RegionOptions");
  check.NonNegative("link_m", link_m, "m");
  check.AtLeast("min_core_points", min_core_points, 1);
}

std::vector<ChangeRegion> FindChangeRegions(const std::vector<CoreDeviation>& deviations,
                                            double core_spacing_m, const RegionOptions& options,
                                            std::vector<int>& region_of) {
  options.Check();
  if (!(core_spacing_m > 0.0)) throw Error("FindChangeRegions: core_spacing_m must be > 0");
  const double link_m = options.link_m > 0.0 ? options.link_m : 1.8 * core_spacing_m;
  std::vector<ChangeRegion> regions;
  for (std::vector<std::size_t>& group : ConnectedGroups(deviations, link_m)) {
    if (static_cast<int>(group.size()) < options.min_core_points) continue;
    regions.push_back(Describe(deviations, std::move(group), core_spacing_m * core_spacing_m));
  }
  // Largest first; ties by the first core point, so the order never depends on the threads.
  std::sort(regions.begin(), regions.end(), [](const ChangeRegion& a, const ChangeRegion& b) {
    return a.core_indices.size() != b.core_indices.size()
               ? a.core_indices.size() > b.core_indices.size()
               : a.core_indices.front() < b.core_indices.front();
  });
  region_of.assign(deviations.size(), -1);
  for (std::size_t k = 0; k < regions.size(); ++k) {
    regions[k].id = static_cast<int>(k);
    for (std::size_t i : regions[k].core_indices) region_of[i] = static_cast<int>(k);
  }
  return regions;
}

}  // namespace uwscan::mapping
