#pragma once

#include <cstddef>

#include "perception/cloud/point_cloud.hpp"

// How large a cloud is and how densely it is sampled, measured so that a few stray points change
// neither: what default sizes (voxels, radii, plausible units) are derived from.
namespace uwscan::perception {

// The diagonal of the box that holds all but the outer 1 % of the points along each axis,
// metres: the cloud's size, not that of a stray return far away. 0 for an empty cloud.
double RobustDiagonal(const PointCloud& cloud);

// The median distance from a point to its nearest other point not at the same place, over up to
// `samples` points taken evenly through the cloud, metres: the scan's sampling step, whether or
// not the file holds each point twice. Deterministic. 0 for a cloud of fewer than two distinct
// points.
double MedianPointSpacing(const PointCloud& cloud, std::size_t samples = 2000);

}  // namespace uwscan::perception
