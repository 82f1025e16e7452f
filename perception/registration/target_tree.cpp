#include "perception/registration/target_tree.hpp"

#include <flann/util/matrix.h>
#include <omp.h>

#include <algorithm>
#include <exception>
#include <numeric>

namespace uwscan::perception {
namespace {

// The axis along which the points' bounding box is widest.
int WidestAxis(const std::vector<Eigen::Vector3f>& points) {
  Eigen::Vector3f low = points.front();
  Eigen::Vector3f high = points.front();
  for (const Eigen::Vector3f& p : points) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  int axis = 0;
  (high - low).maxCoeff(&axis);
  return axis;
}

}  // namespace

TargetTree::Half::Half(std::vector<std::uint32_t> ids_in, const PointCloud& target)
    : ids(std::move(ids_in)),
      points([&] {
        std::vector<Eigen::Vector3f> selected;
        selected.reserve(ids.size());
        for (const std::uint32_t id : ids) selected.push_back(target.points[id]);
        return selected;
      }()),
      index(flann::Matrix<float>(points.front().data(), points.size(), 3),
            flann::KDTreeSingleIndexParams(10)) {}

TargetTree::MedianSplit TargetTree::SplitAtMedian(const PointCloud& target) {
  MedianSplit split;
  split.axis = WidestAxis(target.points);
  std::vector<std::uint32_t> ids(target.size());
  std::iota(ids.begin(), ids.end(), 0u);
  // Ties along the axis go by index, so the halves do not depend on the library's partition.
  const auto below = [&](std::uint32_t a, std::uint32_t b) {
    const float pa = target.points[a][split.axis];
    const float pb = target.points[b][split.axis];
    return pa < pb || (pa == pb && a < b);
  };
  const auto middle = ids.begin() + static_cast<std::ptrdiff_t>(ids.size() / 2);
  std::nth_element(ids.begin(), middle, ids.end(), below);
  split.value = target.points[*middle][split.axis];
  split.low.assign(ids.begin(), middle);
  split.high.assign(middle, ids.end());
  std::sort(split.low.begin(), split.low.end());  // each half in the target's order
  std::sort(split.high.begin(), split.high.end());
  return split;
}

TargetTree::TargetTree(const PointCloud& target, double grid_radius_m, double grid_cell_m,
                       int threads)
    : TargetTree(target, SplitAtMedian(target), grid_radius_m, grid_cell_m, threads) {}

TargetTree::TargetTree(const PointCloud& target, MedianSplit split, double grid_radius_m,
                       double grid_cell_m, int threads)
    : axis_(split.axis),
      split_(split.value),
      low_(std::move(split.low), target),
      high_(std::move(split.high), target) {
  std::exception_ptr low_failure, high_failure;
  const int thread_count = threads > 0 ? threads : omp_get_max_threads();
#pragma omp parallel sections num_threads(std::min(2, thread_count))
  {
#pragma omp section
    {
      try {
        low_.index.buildIndex();
      } catch (...) {
        low_failure = std::current_exception();
      }
    }
#pragma omp section
    {
      try {
        high_.index.buildIndex();
      } catch (...) {
        high_failure = std::current_exception();
      }
    }
  }
  if (low_failure) std::rethrow_exception(low_failure);
  if (high_failure) std::rethrow_exception(high_failure);
  if (grid_radius_m > 0.0) {
    grid_.emplace(target.points, grid_cell_m > 0.0 ? grid_cell_m : 0.25 * grid_radius_m,
                  grid_radius_m);
    grid_radius_sq_ = static_cast<float>(grid_radius_m * grid_radius_m);
  }
}

}  // namespace uwscan::perception
