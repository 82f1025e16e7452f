#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <optional>
#include <vector>

#include "perception/cloud/point_cloud.hpp"
#include "perception/registration/registration_result.hpp"

namespace uwscan::perception {

enum class IcpMethod {
  kPointToPoint,  // Besl & McKay 1992: closed-form SVD step on the pairs (AlignSvd)
  kPointToPlane   // Chen & Medioni 1992: linearised step on n . (p - q); needs target normals
};

// A prior on the pose, in information form (e.g. the navigation's estimate of a motion), for
// point-to-plane: each step then minimises
//   sum_i r_i^2 / point_sigma_m^2 + e^T information e,
// e = [w (rad), v (m)], the left perturbation taking T_target_source to the current pose:
// a rotation by w about the target cloud's origin, then a translation by v. Directions the
// points do not constrain (a flat seabed, a single pipe) then follow the prior instead of
// staying wherever the start put them.
struct IcpPrior {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> information = Eigen::Matrix<double, 6, 6>::Zero();  // symmetric PSD
  double point_sigma_m = 0.001;  // std of one point-to-plane residual, metres, > 0
};

struct IcpOptions {
  IcpMethod method = IcpMethod::kPointToPoint;
  int max_iterations = 100;           // iterations over all stages together, > 0
  int max_iterations_per_stage = 50;  // iterations of one stage of the schedule, > 0
  // Stages of the schedule, metres: a pair is used only if the target point is within this
  // distance of the moved source point. Each stage runs until convergence or its cap. Non-empty,
  // finite, > 0 and non-increasing.
  std::vector<double> max_correspondence_distance_m = {0.05, 0.02, 0.01};
  // A stage has converged when an iteration's increment rotates by less than
  // rotation_tolerance_rad and moves the target centroid by less than translation_tolerance_m,
  // or when the RMS residual changed by less than relative_rmse_tolerance of its value. All >= 0,
  // relative_rmse_tolerance < 1.
  double rotation_tolerance_rad = 1e-6;   // radians
  double translation_tolerance_m = 1e-6;  // metres
  double relative_rmse_tolerance = 1e-6;  // dimensionless
  // Stages before the last converge at this many times the three tolerances above: each only
  // has to bring the pose within the next stage's reach, and the last settles it. >= 1.
  double early_stage_tolerance_scale = 1.0;
  // When > 0, a stage also ends (not converged) once its RMS residual has not gone below its
  // lowest so far by relative_rmse_tolerance for this many iterations, and the pose goes back to
  // where the residual was lowest. Changing pairs can make ICP cycle between poses (a pipe
  // rolling about its axis, a wrong object's pose hopping between two fits) until its cap; this
  // ends that. 0 = off, >= 0.
  int stall_iterations = 0;
  // Point-to-plane without a prior only (else 0): when > 0, the step tolerances are tested only
  // on the part of each step along directions the pairs determine well (eigenvalues of J^T J,
  // rotations scaled by the pairs' lever arm, at least this fraction of the largest). A pipe then
  // converges although it keeps rolling about and sliding along its axis, where nothing pins it
  // (the result's information says which directions are free). In [0, 1); 0 = every direction.
  double weak_direction_ratio = 0.0;
  int threads = 0;  // OpenMP threads for the nearest-neighbour search, 0 = OpenMP's default, >= 0
  // When > 0, a source point pairs only with target points whose normal is within this angle of
  // its own (rotated) normal; both clouds then need normals, facing the same way (a scan's
  // towards the sensor, a model's outwards). This keeps a scan of a pipe's outside off the
  // model's inner wall a few millimetres below it, where the point-to-plane distances are small
  // but the surface faces the other way. Radians, in [0, pi]; 0 = off.
  double max_normal_angle_rad = 0.0;
  // Point-to-plane only; with a prior, rotations are linearised about the target origin.
  std::optional<IcpPrior> prior;

  // Throws uwscan::Error naming the field when a value is out of range.
  void Check() const;
};

// Iterative closest point alignment of source onto target, starting at T_target_source_init.
// Each iteration pairs every moved source point with its nearest target point (a k-d tree on
// the target, built once; queries in parallel over source points), drops pairs farther apart
// than the stage's distance and solves for an increment:
//   point-to-point: the rigid transform minimising sum |p - q|^2 in closed form (AlignSvd);
//   point-to-plane: one Gauss-Newton step on sum (n_q . (p - q))^2 with the rotation
//     linearised about the target centroid, solved by the eigen-decomposition of J^T J with
//     eigenvalues below 1e-10 x the largest dropped, so unconstrained directions (a single
//     plane) do not move instead of running away; the rotation is then applied exactly.
// Stages run in order of options.max_correspondence_distance_m.
//
// Precision: all geometry in double relative to target.origin; clouds whose origins differ by
// 1e6 m align as well as nearby ones. Determinism: sums run in fixed blocks of points and are
// added in a fixed order, so any thread count gives the same bits.
//
// Result, evaluated at the returned transform with the last stage's distance:
//   fitness = fraction of source points with a target point within that distance (and within
//     the normal gate, when there is one);
//   inlier_rmse = RMS of |p - q| over those pairs, metres (point-to-point distance for both
//     methods);
//   iterations = iterations over all stages;
//   converged = the last stage met a tolerance within its cap and options.max_iterations; false
//     also when it stalled (options.stall_iterations), when an iteration found fewer than 3
//     pairs (it stops there) or, for point-to-point, the pairs were collinear (AlignSvd
//     degenerate);
//   information = sum over those pairs of J^T J with the pose perturbed as
//     p -> p + w x p + v, p relative to target.origin, ordered [w (rad), v (m)]:
//     point-to-plane rows [(p x n)^T, n^T]; point-to-point 3 rows per pair [-[p]x, I].
//     Its near-zero eigenvalues are the directions the pairs do not constrain (3 for a single
//     plane with point-to-plane: the in-plane translations and the rotation about the normal;
//     the point-to-point information does not see that sliding, as fixed pairs pin all 6).
// Throws uwscan::Error when a cloud has fewer than 3 points or a non-finite point or normal,
// point-to-plane is asked for and the target has no normals, T_target_source_init is not
// finite or not a rotation plus translation, or the options are invalid.
RegistrationResult AlignIcp(const PointCloud& source, const PointCloud& target,
                            const Eigen::Isometry3d& T_target_source_init,
                            const IcpOptions& options = {});

class NearestGrid;

// The target of ICP prepared once (checked, its k-d tree and centroid), for aligning many
// sources or many starting poses onto the same cloud, e.g. pose hypotheses on an object model.
// Keeps a reference to `cloud`, which must outlive it unchanged (a temporary is refused at
// compile time). AlignIcp may run on one target from several threads at once. Throws
// uwscan::Error when the cloud has fewer than 3 points or a non-finite point or normal.
class IcpTarget {
 public:
  // grid_radius_m > 0: searches within up to that radius use a grid (NearestGrid) of cells of
  // grid_cell_m (0: a quarter of the radius), faster than the tree when the target's points are
  // about a cell apart; the same pairs either way (of equally near points the grid takes the
  // lowest index). grid_cell_m in [0, grid_radius_m]. threads (0: all) build the search trees;
  // the trees and every answer are the same for any count.
  explicit IcpTarget(const PointCloud& cloud, double grid_radius_m = 0.0, double grid_cell_m = 0.0,
                     int threads = 0);
  IcpTarget(const PointCloud&&, double = 0.0, double = 0.0, int = 0) = delete;
  ~IcpTarget();
  IcpTarget(const IcpTarget&) = delete;
  IcpTarget& operator=(const IcpTarget&) = delete;

  const PointCloud& cloud() const { return cloud_; }
  // The grid searches within grid_radius_m use (cells a quarter of it), for other exact nearest
  // queries on the same points; nullptr when grid_radius_m is 0.
  const NearestGrid* grid() const;

 private:
  friend RegistrationResult AlignIcp(const PointCloud&, const IcpTarget&, const Eigen::Isometry3d&,
                                     const IcpOptions&);
  struct Tree;
  const PointCloud& cloud_;
  std::unique_ptr<Tree> tree_;
  Eigen::Vector3d centroid_rel_;  // relative to cloud_.origin
};

// AlignIcp onto a prepared target: the same result as AlignIcp(source, target.cloud(), ...).
RegistrationResult AlignIcp(const PointCloud& source, const IcpTarget& target,
                            const Eigen::Isometry3d& T_target_source_init,
                            const IcpOptions& options = {});

}  // namespace uwscan::perception
