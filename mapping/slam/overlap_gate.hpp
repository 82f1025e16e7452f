#pragma once

#include <Eigen/Core>

// The loop-closure gate: could two submaps overlap, given how uncertain their relative position is?
namespace uwscan::mapping {

// The smallest Mahalanobis norm, under `covariance` (3x3, symmetric PSD, m^2), of an error in a
// predicted position that brings a point predicted at `gap_m` from another to within
// `overlap_m` of it: min sqrt(d^T C^-1 d) over |gap + d| <= overlap_m. Zero when they already
// overlap; infinite when the gap lies along directions without variance, or an input is not
// finite (a gate fails closed). A gap along the uncertainty's long axis is plausible; the same
// gap along a narrow one is not.
//
// Solved in C's eigenbasis: the minimiser is d = -(I + lambda C)^-1 lambda C gap for the
// lambda >= 0 that puts gap + d on the sphere, found by bisection (|gap + d| falls as lambda
// grows). A direction with no variance (eigenvalue <= 1e-300 m^2) cannot move.
double MahalanobisGapToOverlap(const Eigen::Vector3d& gap_m, double overlap_m,
                               const Eigen::Matrix3d& covariance);

}  // namespace uwscan::mapping
