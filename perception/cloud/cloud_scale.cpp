#include "perception/cloud/cloud_scale.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "perception/cloud/cloud_neighbors.hpp"

namespace uwscan::perception {

double RobustDiagonal(const PointCloud& cloud) {
  if (cloud.empty()) return 0.0;
  std::vector<float> values(cloud.size());
  const std::size_t outer = values.size() / 100;
  Eigen::Vector3d low, high;
  for (int axis = 0; axis < 3; ++axis) {
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = cloud.points[i][axis];
    std::nth_element(values.begin(), values.begin() + outer, values.end());
    low[axis] = values[outer];
    std::nth_element(values.begin(), values.end() - 1 - outer, values.end());
    high[axis] = values[values.size() - 1 - outer];
  }
  return (high - low).norm();
}

// Neighbours searched per sampled point for one that is not at its place.
constexpr int kNeighbours = 8;

double MedianPointSpacing(const PointCloud& cloud, std::size_t samples) {
  if (cloud.size() < 2 || samples == 0) return 0.0;
  const KnnIndex index(cloud.points);
  const std::size_t step = std::max<std::size_t>(1, cloud.size() / samples);
  std::vector<double> nearest_m;
  std::vector<std::uint32_t> indices;
  std::vector<float> squared_m2;
  for (std::size_t i = 0; i < cloud.size(); i += step) {
    // The nearest is the point itself, then perhaps twins at the same place (scans written
    // twice over, or returns at the sensor's origin): the first point away from it.
    index.Query(cloud.points[i], kNeighbours, indices, squared_m2);
    const auto away =
        std::find_if(squared_m2.begin(), squared_m2.end(), [](float d) { return d > 0.0f; });
    if (away != squared_m2.end()) nearest_m.push_back(std::sqrt(static_cast<double>(*away)));
  }
  if (nearest_m.empty()) return 0.0;
  const auto middle = nearest_m.begin() + static_cast<std::ptrdiff_t>(nearest_m.size() / 2);
  std::nth_element(nearest_m.begin(), middle, nearest_m.end());
  return *middle;
}

}  // namespace uwscan::perception
