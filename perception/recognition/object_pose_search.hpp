#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/cloud/nearest_grid.hpp"
#include "perception/cloud/point_cloud.hpp"
#include "perception/features/fpfh.hpp"
#include "perception/recognition/object_database.hpp"
#include "perception/recognition/object_recognizer.hpp"
#include "perception/registration/icp.hpp"

namespace uwscan::perception {

// The pose search of RecognizeObjects: starting poses of a segment on an object model, sifted
// by a short ICP, the best ones for the fine ICP.

// A database view's points with normals (facing its camera at the origin) and FPFH at every one.
struct ViewFeatures {
  PointCloud cloud;
  FpfhFeatures features;
};
ViewFeatures DescribeView(const ObjectView& view, const ObjectDatabaseParameters& p, int threads);

// The sift's widest pair distance for an object (SiftStarts' first stage): a tenth of its size
// (a roll step off at its rim), at least 8 voxels, metres.
double SiftReach(double diameter_m, double voxel_m);

// A model's search structures: its ICP target, whose grid of one-voxel cells (the model's points
// are about a voxel apart) answers every pair search of the pose search, out to the sift's reach
// (beyond the fine ICP's 4 voxels), and the nearest model points for verification, parts and
// symmetry phases. Searched through the grid the sift took 12 % less time than through the k-d
// tree (recognition bench, seed 2), with the same pairs.
struct ModelIndexes {
  ModelIndexes(const ObjectModel& model, double voxel_m)
      : target(model.model, SiftReach(model.diameter_m, voxel_m), voxel_m) {}
  IcpTarget target;
  const NearestGrid& nearest() const { return *target.grid(); }
};

// What recognition derives from a database and comes back to segment after segment and scan
// after scan: the features of its views and its models' search structures, each computed the
// first time it is asked for and kept. Safe to use from several threads; what it returns does
// not depend on which call computed it.
class RecognitionCache {
 public:
  explicit RecognitionCache(const ObjectDatabase& db) : db_(db) {}
  const ViewFeatures& View(std::size_t object, std::size_t view, int threads);
  const ModelIndexes& Model(std::size_t object);
  const ObjectDatabase& db() const { return db_; }

 private:
  const ObjectDatabase& db_;
  std::mutex mutex_;
  std::map<std::pair<std::size_t, std::size_t>, std::unique_ptr<ViewFeatures>> described_;
  std::map<std::size_t, std::unique_ptr<ModelIndexes>> models_;
};

// Half turns about the three principal axes of a cloud through its centroid (T_new_old).
std::vector<Eigen::Isometry3d> HalfTurns(const PointCloud& cloud);

// Point-to-plane ICP of a segment onto a model, to the scale of the data, pairing only points
// whose normals agree within 60 degrees (the segment's facing the sensor, the model's outwards).
IcpOptions FineIcp(double diameter_m, const ObjectDatabaseParameters& p, int threads);
// FineIcp's last stage alone: the pass on every point of a segment once a pose has converged on
// a sample (the pose barely moves; its information is that of every point).
IcpOptions FineIcpLastStage(double diameter_m, const ObjectDatabaseParameters& p, int threads);

// Starting poses T_O_S of a segment on one object: FPFH + RANSAC onto its nearest view (when
// RANSAC finds one), then each of its nearest `options.pose_views` views rolled about the line
// of sight. `views`: (chi-square, view index) of the object's nearest views, nearest first.
std::vector<Eigen::Isometry3d> PoseStarts(const PointCloud& segment,
                                          const FpfhFeatures& segment_features, std::size_t object,
                                          const std::vector<std::pair<double, int>>& views,
                                          RecognitionCache& cache, const ObjectDatabase& db,
                                          const RecognitionOptions& options);

// The starts worth a full ICP: each gets a short ICP on a strided subset of the segment, and
// the `options.refined_starts` best distinct poses it reached by fit (then by order) are
// returned, best first. The fit is taken at two voxels, where a start in the right basin
// already has the segment on the model and a wrong one does not. The best pose is also tried
// turned half a turn about each principal axis of the model: a nearly symmetric object (a
// valve's body) fits either way, and only a detail (its handle) decides. Parallel over starts,
// chosen in a fixed order: the same for any thread count.
std::vector<Eigen::Isometry3d> SiftStarts(const PointCloud& segment, const IcpTarget& target,
                                          const std::vector<Eigen::Isometry3d>& starts,
                                          double diameter_m, const ObjectDatabaseParameters& p,
                                          const RecognitionOptions& options);

// Sum over `sample` (segment frame) of the squared point-to-plane distances to the nearest
// points of the model posed by T_O_S, each at most voxel_m^2: a point farther than a voxel from
// every model point counts the cap, as no pair at all. `model_grid` holds model.model's points.
double TruncatedResidual(const PointCloud& sample, const ObjectModel& model,
                         const NearestGrid& model_grid, const Eigen::Isometry3d& T_O_S,
                         double voxel_m);

// Phases worth trying about one of the model's symmetry axes of order N >= 3 (a surface of
// revolution whose details repeat N times: a flange's bolt heads): the pose turned about the
// axis in steps of about half a voxel at the object's rim over one period (2 pi / N), each
// scored by TruncatedResidual; returned are the lowest turn and the middle of the run of turns
// within half a point's cap of it (small details sampled at the voxel fit alike over a few
// steps), those other than the pose itself. ICP alone does not find that phase: the details
// stand off the surface beyond its pairing distance unless they already overlap. T_O_S as ICP
// gives it (segment to object), and the same for the results.
std::vector<Eigen::Isometry3d> SymmetryPhaseStarts(const PointCloud& sample,
                                                   const ObjectModel& model,
                                                   const NearestGrid& model_grid,
                                                   const SymmetryAxis& axis,
                                                   const Eigen::Isometry3d& T_O_S, double voxel_m);

// Whether the data pins the pose's phase about one of the model's symmetry axes of order N >= 3:
// some turn over the period (as SymmetryPhaseStarts turns it) puts at least `min_points` points'
// worth of TruncatedResidual (voxel_m^2 each) more off the model than another. A flange seen
// from its face shows a surface of revolution, its bolt heads behind it: every phase fits alike,
// which the ICP's information does not show (the faceted model and its estimated normals are not
// quite a surface of revolution, which makes the turn look pinned). True for an axis of lower
// order, which has no phase.
bool SymmetryPhasePinned(const PointCloud& sample, const ObjectModel& model,
                         const NearestGrid& model_grid, const SymmetryAxis& axis,
                         const Eigen::Isometry3d& T_O_S, double voxel_m, double min_points);

}  // namespace uwscan::perception
