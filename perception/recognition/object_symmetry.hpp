#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <vector>

#include "scanner/common/triangle_mesh.hpp"

namespace uwscan::perception {

// A rotational symmetry of an object: turning it about the axis through point_O by 2 pi / order
// (order >= 2), or by any angle (order 0, continuous), leaves its surface where it was.
struct SymmetryAxis {
  Eigen::Vector3d point_O = Eigen::Vector3d::Zero();  // metres, object frame
  Eigen::Vector3d axis_O = Eigen::Vector3d::UnitZ();  // unit
  int order = 0;                                      // 0 = continuous, else N-fold (N >= 2)
  bool continuous() const { return order == 0; }
};

// Every pose of the object indistinguishable from the identity: the products of one rotation
// per axis (identity included), continuous axes sampled every continuous_step_rad. Transforms
// T_O_O' (a point x of the turned object is at T x).
std::vector<Eigen::Isometry3d> SymmetryTransforms(std::span<const SymmetryAxis> axes,
                                                  double continuous_step_rad = 0.0872664626);

struct SymmetryDetectionOptions {
  int samples = 60000;                // surface samples of the mesh, >= 1000
  int test_points = 3000;             // samples moved and compared per tested rotation, >= 100
  int max_order = 12;                 // largest N-fold symmetry looked for, >= 2
  double tolerance_fraction = 0.005;  // of the diameter, added to twice the sample spacing
  std::uint64_t seed = 1;
  void Check() const;  // throws uwscan::Error naming the field
};

// The symmetries of a mesh about its three principal axes through the centroid of its surface:
// a rotation is a symmetry when no moved test sample lies farther from the surface samples
// than the tolerance. Continuous when three unrelated angles all pass, else the largest
// passing N-fold. Throws uwscan::Error on an empty mesh or invalid options.
std::vector<SymmetryAxis> DetectSymmetries(const scanner::TriangleMesh& mesh,
                                           const SymmetryDetectionOptions& options = {});

// An estimated object pose against the truth, modulo the object's symmetries (DESIGN.md's
// evaluation conventions): the symmetric equivalent of the truth nearest the estimate by MSSD.
struct SymmetricPoseError {
  double mssd_m = 0.0;         // max over model points of |T_est x - T_true S x|, min over S
  double rotation_rad = 0.0;   // angle of (T_true S)^-1 T_est for that S
  double translation_m = 0.0;  // |t_est - t_(T_true S)|
  Eigen::Isometry3d T_symmetric =
      Eigen::Isometry3d::Identity();  // T_true S, the truth measured against
};
// `symmetries` as SymmetryTransforms gives them (at least the identity); model points in {O}.
// Throws uwscan::Error when either is empty.
SymmetricPoseError PoseErrorModuloSymmetry(const Eigen::Isometry3d& T_est,
                                           const Eigen::Isometry3d& T_true,
                                           std::span<const Eigen::Vector3d> model_points_O,
                                           std::span<const Eigen::Isometry3d> symmetries);

// The same with the symmetries given as axes: the branch found among SymmetryTransforms(axes),
// then the angle about each continuous axis chosen exactly, as the turn about it that brings the
// truth's orientation nearest the estimate's. A pipe rolled about its axis by an angle between
// two samples (5 degrees apart) then counts no rotation error for the roll, only for the tilt.
SymmetricPoseError PoseErrorModuloSymmetry(const Eigen::Isometry3d& T_est,
                                           const Eigen::Isometry3d& T_true,
                                           std::span<const Eigen::Vector3d> model_points_O,
                                           std::span<const SymmetryAxis> axes);

}  // namespace uwscan::perception
