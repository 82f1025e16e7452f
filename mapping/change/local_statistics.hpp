#pragma once

#include <vector>

#include "mapping/change/surface_deviation.hpp"

namespace uwscan::mapping {

// What the deviations around each core point say about it: within a radius, among the
// inspected core points whose normals lie within an angle of its own (the same surface, not the
// pipe beside the seabed), one per cell of a grid a tenth of the radius wide.

// Takes out, at each inspected core point, the median deviation of its neighbourhood (that of its
// cell's sample, which the points of one cell share): the slowly varying offsets the two surveys'
// placement errors leave after registration (a millimetre or two at the far edges of a swath, where
// a small tilt of the sensor moves the surface most). A change covering less than half the
// neighbourhood keeps its depth; a wider one is taken for an offset and shrinks. The status is not
// touched. radius_m > 0.
void RemoveLocalOffsets(std::vector<CoreDeviation>& deviations, double radius_m,
                        double max_normal_angle_rad);

// Whether each core point lies near an edge of the compared surface: inspected, with fewer than
// 85 % of the median count of inspected core points within radius_m (an edge within about 0.6
// radii) because a swath ends there, a shadow or a hole begins, or the reference stops. The last
// centimetres of a swath are where the two surveys agree least (on the change bench 12 % of the
// unchanged points within 3 cm of an edge fell in false regions, against 1.4 % elsewhere), so
// they form spread groups of their own (AddGroupSpread). radius_m > 0.
std::vector<char> AtSurfaceEdge(const std::vector<CoreDeviation>& deviations, double radius_m);

// Adds to each inspected core point's level of detection the spread of its group's deviations
// that their own levels do not explain: the robust spread (the third quartile of the absolute
// deviations from their median, over 1.1503, its value for a Gaussian of unit sigma) squared, less
// the median of their variances (lod / z)^2 when positive. A group is a patch of one kind of
// surface (a registration tile's seabed, or its structure): how reproducibly the two surveys place
// that surface there, measured on the surface itself as M3C2 practice measures registration error
// on stable ground. A change covering less than a quarter of its group barely moves it. group_of[i]
// < 0: no group (left as it is). The status is updated; z is the level of detection's quantile.
void AddGroupSpread(std::vector<CoreDeviation>& deviations, const std::vector<long>& group_of,
                    double z);

}  // namespace uwscan::mapping
