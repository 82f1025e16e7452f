#pragma once

#include <Eigen/Core>
#include <vector>

#include "mapping/change/survey.hpp"

namespace uwscan::mapping {

// How well a survey placed each core point's surface relative to the rest of its registration
// tile, from its poses' joint uncertainty (Survey::joint_uncertainty).
//
// A map point is the mean of what the submaps that swept over it saw, so it moves with the mean
// error of their poses; a tile's registration takes out what moves the whole tile. At a point p
// seen from the poses P(p), in a tile whose core points give the poses weights w_i (the mean of
// each point's equal shares over P(p)), what is left along the normal n is
//   n . sum_i (1{i in P(p)} / |P(p)| - w_i) J_i(p) e_i,  J_i(p) e = w x (p - t_i) + v
// for a pose error e = [w, v] about the pose's position t_i. Its variance comes from the poses'
// joint covariance: legs of a dive tied by a loop closure are placed alike and leave little; a
// leg the graph holds loosely against the others leaves its own uncertainty. The marginal
// covariances cannot say this: they hold the whole dive's drift, which the registration removes.
//
// P(p): the poses no more than `seen_within_m` farther from p than the nearest pose is (the
// submaps whose sweeps covered it; metres, >= 0). points_S and normals_S: the core points and
// their unit normals in the survey's frame; tile_of: each core point's tile (any id; < 0: the
// whole survey's). Returns the standard deviation along each normal (metres); all 0 when the
// survey has no joint uncertainty or it is singular.
std::vector<double> TileRelativePoseSigmas(const Survey& survey,
                                           const std::vector<Eigen::Vector3d>& points_S,
                                           const std::vector<Eigen::Vector3d>& normals_S,
                                           const std::vector<long>& tile_of, double seen_within_m);

}  // namespace uwscan::mapping
