#include "mapping/change/local_statistics.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <functional>
#include <map>

#include "perception/cloud/cloud_neighbors.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

double MedianOf(std::vector<double>& values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// The q-quantile of values (the element of rank floor(q (n - 1)), no interpolation), q in [0, 1];
// reorders values, which must not be empty.
double QuantileOf(std::vector<double>& values, double q) {
  assert(!values.empty());
  const auto at =
      values.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

// |z| of a standard Gaussian at its third quartile: P(|z| < 1.1503) = 0.75.
constexpr double kGaussianThirdQuartileOfAbs = 1.1503;

// The inspected core points sampled one per cell of a grid (a tenth of the radius) and way of
// facing, so that a wide neighbourhood costs a few hundred points, not thousands: calls
// visit(s, neighbours) for each sample s with its neighbourhood, the samples within radius_m
// facing the same way, and returns each core point's sample (-1 where not inspected). What varies
// over the radius barely changes within a cell, so a core point takes its sample's. In parallel;
// visit must only write to what belongs to s.
std::vector<std::ptrdiff_t> ForEachNeighbourhood(
    const std::vector<CoreDeviation>& deviations, double radius_m, double max_normal_angle_rad,
    const std::function<void(std::size_t, const std::vector<std::size_t>&)>& visit) {
  if (!(radius_m > 0.0)) throw Error("local statistics: radius_m must be > 0");
  std::vector<std::ptrdiff_t> sample_of(deviations.size(), -1);
  std::vector<std::size_t> sample;
  std::vector<Eigen::Vector3f> points;
  std::map<std::array<long, 4>, std::size_t> taken;
  const double cell_m = 0.1 * radius_m;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < deviations.size(); ++i) {
    if (deviations[i].status == SurfaceStatus::kNotInspected) continue;
    if (sample.empty()) origin = deviations[i].point_W;
    const Eigen::Vector3d p = deviations[i].point_W - origin;
    // One per cell and per way of facing (the normal's largest component and its sign): a box's
    // side and the seabed at its foot share cells, not samples.
    Eigen::Index axis = 0;
    deviations[i].normal_W.cwiseAbs().maxCoeff(&axis);
    const long facing = 2 * axis + (deviations[i].normal_W(axis) > 0.0 ? 1 : 0);
    const std::array<long, 4> key = {std::lround(std::floor(p.x() / cell_m)),
                                     std::lround(std::floor(p.y() / cell_m)),
                                     std::lround(std::floor(p.z() / cell_m)), facing};
    const auto [it, added] = taken.emplace(key, i);
    sample_of[i] = static_cast<std::ptrdiff_t>(it->second);
    if (!added) continue;
    sample.push_back(i);
    points.push_back(p.cast<float>());
  }
  if (sample.empty()) return sample_of;
  const perception::RadiusGrid grid(points, radius_m);
  const double min_cos = std::cos(max_normal_angle_rad);
#pragma omp parallel
  {
    std::vector<std::uint32_t> found;
    std::vector<float> d2;
    std::vector<std::size_t> neighbours;
#pragma omp for schedule(dynamic, 64)
    for (std::size_t k = 0; k < sample.size(); ++k) {
      const CoreDeviation& d = deviations[sample[k]];
      grid.Query(points[k], found, d2);
      neighbours.clear();
      for (std::uint32_t j : found) {
        if (deviations[sample[j]].normal_W.dot(d.normal_W) >= min_cos)
          neighbours.push_back(sample[j]);
      }
      visit(sample[k], neighbours);  // never empty: the sample itself is among them
    }
  }
  return sample_of;
}

}  // namespace

void RemoveLocalOffsets(std::vector<CoreDeviation>& deviations, double radius_m,
                        double max_normal_angle_rad) {
  std::vector<double> offsets(deviations.size(), 0.0);
  const std::vector<std::ptrdiff_t> sample_of =
      ForEachNeighbourhood(deviations, radius_m, max_normal_angle_rad,
                           [&](std::size_t s, const std::vector<std::size_t>& neighbours) {
                             std::vector<double> values;
                             for (std::size_t n : neighbours)
                               values.push_back(deviations[n].deviation_m);
                             offsets[s] = MedianOf(values);
                           });
  for (std::size_t i = 0; i < deviations.size(); ++i) {
    if (sample_of[i] >= 0)
      deviations[i].deviation_m -= offsets[static_cast<std::size_t>(sample_of[i])];
  }
}

std::vector<char> AtSurfaceEdge(const std::vector<CoreDeviation>& deviations, double radius_m) {
  // A disc missing 15 % of its area is cut by an edge about 0.6 radii from its centre.
  constexpr double kWholeShare = 0.85;
  if (!(radius_m > 0.0)) throw Error("AtSurfaceEdge: radius_m must be > 0");
  std::vector<std::size_t> inspected;
  for (std::size_t i = 0; i < deviations.size(); ++i)
    if (deviations[i].status != SurfaceStatus::kNotInspected) inspected.push_back(i);
  std::vector<char> edge(deviations.size(), 0);
  if (inspected.empty()) return edge;
  const Eigen::Vector3d origin = deviations[inspected.front()].point_W;
  std::vector<Eigen::Vector3f> points;
  for (std::size_t i : inspected) points.push_back((deviations[i].point_W - origin).cast<float>());
  const perception::RadiusGrid grid(points, radius_m);
  std::vector<double> counts(points.size());
#pragma omp parallel
  {
    std::vector<std::uint32_t> found;
    std::vector<float> d2;
#pragma omp for schedule(static)
    for (std::size_t k = 0; k < points.size(); ++k) {
      grid.Query(points[k], found, d2);
      counts[k] = static_cast<double>(found.size());
    }
  }
  std::vector<double> sorted = counts;
  const double whole = kWholeShare * MedianOf(sorted);
  for (std::size_t k = 0; k < points.size(); ++k) edge[inspected[k]] = counts[k] < whole;
  return edge;
}

void AddGroupSpread(std::vector<CoreDeviation>& deviations, const std::vector<long>& group_of,
                    double z) {
  std::map<long, std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < deviations.size(); ++i) {
    if (deviations[i].status != SurfaceStatus::kNotInspected && group_of[i] >= 0)
      groups[group_of[i]].push_back(i);
  }
  for (const auto& [group, members] : groups) {
    std::vector<double> values, variances;
    for (std::size_t i : members) {
      values.push_back(deviations[i].deviation_m);
      variances.push_back(std::pow(deviations[i].lod_m / z, 2));
    }
    const double median = MedianOf(values);
    for (double& v : values) v = std::abs(v - median);
    // The third quartile of |deviation - median|, not its median: the groups' deviations have
    // heavier tails than a Gaussian (placement offsets of a millimetre or two over patches), which
    // a 95 % level of detection must take in. A change covering a quarter of its group moves it.
    const double spread = QuantileOf(values, 0.75) / kGaussianThirdQuartileOfAbs;
    const double unexplained = std::max(0.0, spread * spread - MedianOf(variances));
    for (std::size_t i : members) {
      CoreDeviation& d = deviations[i];
      d.lod_m = z * std::sqrt(std::pow(d.lod_m / z, 2) + unexplained);
      d.status =
          std::abs(d.deviation_m) > d.lod_m ? SurfaceStatus::kChanged : SurfaceStatus::kUnchanged;
    }
  }
}

}  // namespace uwscan::mapping
