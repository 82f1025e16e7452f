#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "mapping/slam/pose_graph.hpp"
#include "perception/cloud/point_cloud.hpp"

// What a registration's pairs measure, as the mapper hands it to the pose graph: the ICP
// information with the directions the scene does not pin taken out (mapper.cpp; internal to
// mapping/). Information and covariances in the pose graph's [w (rad), v (m)] about the target
// origin (pose_graph.hpp).
namespace uwscan::mapping {

struct KeptDirections {
  Matrix6d information = Matrix6d::Zero();  // weak directions removed, slides exactly
  int count = 0;                            // directions kept (0 to 6)
  Matrix6d covariance = Matrix6d::Zero();   // of what the kept directions measure, 0 elsewhere
  std::vector<Eigen::Vector3d> slides;  // pure translations taken out, orthonormal, target frame
};

// The information with its weakly constrained directions removed: a normalised eigenvalue
// (rotations about the source's centroid, scaled by its RMS radius, so that both are
// displacements of the data) below `ratio` of the largest. Along a pipe or over a flat seabed
// the pairs still sum to something there, but ICP's answer is the noise's, not the scene's; the
// navigation decides those. A removed direction that is mostly translation (a slide) is taken
// out exactly.
KeptDirections WithoutWeakDirections(const Matrix6d& information,
                                     const perception::PointCloud& source,
                                     const Eigen::Isometry3d& T_target_source, double ratio);

// How many directions a cloud's own surface pins: the point-to-plane information of its points
// on their own normals, with the weak directions counted out as WithoutWeakDirections does. A
// registration of this cloud as the source pins at most about as many, whatever the target: a
// bare seabed gives 3 (depth, roll, pitch), a pipe without its ends 5. The cloud must have normals.
int SurfaceDirections(const perception::PointCloud& cloud, double ratio);

// Where a registration leaves a slide free (a pipe seen without its ends), the scan's position
// along it is not measured at all: it is tied to its anchor there only with sigma_m, so that
// what the pairs leak along the slide moves the scan and not the vehicle (through the anchor,
// the dead reckoning's scale error would take it up). `slides` in the target's frame, the
// covariance in the source's.
Matrix6d SlideCovariance(const std::vector<Eigen::Vector3d>& slides,
                         const Eigen::Isometry3d& T_target_source, double sigma_m);

// The 99.9 % quantile of the chi-square distribution with `dof` degrees of freedom (1 to 6).
double Chi2Quantile999(int dof);

}  // namespace uwscan::mapping
