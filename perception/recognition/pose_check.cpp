#include "perception/recognition/pose_check.hpp"

#include <algorithm>
#include <cstdint>
#include <map>
#include <string>

#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/cloud/nearest_grid.hpp"
#include "perception/preprocessing/voxel_filter.hpp"
#include "perception/recognition/object_pose_search.hpp"
#include "perception/recognition/recognition_verification.hpp"
#include "perception/recognition/scan_segments.hpp"
#include "perception/recognition/segment_pose.hpp"
#include "perception/registration/icp.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

// The voxelised scan's points off every support plane that are nearest to a point of `segment`:
// the segment as recognition's own segmentation would hand it over.
std::vector<std::size_t> SegmentInVoxels(const PointCloud& scan,
                                         const std::vector<std::size_t>& segment,
                                         const PointCloud& down, const KnnIndex& down_index,
                                         const std::vector<DetectedPlane>& planes) {
  std::vector<bool> on_plane(down.size(), false);
  for (const DetectedPlane& plane : planes) {
    for (std::size_t i : plane.inliers) on_plane[i] = true;
  }
  std::vector<bool> taken(down.size(), false);
  std::vector<std::uint32_t> nearest;
  std::vector<float> squared;
  const Eigen::Vector3f shift = (scan.origin - down.origin).cast<float>();
  for (std::size_t i : segment) {
    down_index.Query(scan.points[i] + shift, 1, nearest, squared);
    if (!on_plane[nearest[0]]) taken[nearest[0]] = true;
  }
  std::vector<std::size_t> voxels;
  for (std::size_t i = 0; i < down.size(); ++i) {
    if (taken[i]) voxels.push_back(i);
  }
  return voxels;
}

// The ICP's fitness of `segment` moved by T_O_S onto the model, without the ICP: the share of its
// points with a model point within `distance_m` (no normal gate).
double FitnessAt(const PointCloud& segment, const ObjectModel& model, const NearestGrid& model_grid,
                 const Eigen::Isometry3d& T_O_S, double distance_m) {
  std::size_t near = 0;
  const float reach = static_cast<float>(distance_m * distance_m);
  for (std::size_t i = 0; i < segment.size(); ++i) {
    const Eigen::Vector3d p_O = T_O_S * segment.Point(i) - model.model.origin;
    near += model_grid.Nearest(p_O.cast<float>(), reach) >= 0 ? 1 : 0;
  }
  return segment.empty() ? 0.0 : static_cast<double>(near) / static_cast<double>(segment.size());
}

}  // namespace

RecognitionCandidate CheckObjectPose(const PointCloud& scan,
                                     const std::vector<std::size_t>& segment,
                                     const ObjectDatabase& db, RecognitionCache& cache,
                                     const std::string& object_id, const Eigen::Isometry3d& T_S_O,
                                     const RecognitionOptions& options) {
  options.Check();
  if (&cache.db() != &db)
    throw Error("pose check: the RecognitionCache was made for another object database");
  RequireValidCloud(scan, "scan", 1);
  const auto found = std::find_if(db.objects.begin(), db.objects.end(),
                                  [&](const ObjectModel& o) { return o.id == object_id; });
  if (found == db.objects.end())
    throw Error("pose check: object '" + object_id + "' is not in the database");
  if (segment.empty()) throw Error("pose check: the segment is empty");
  for (std::size_t i : segment) {
    if (i >= scan.size())
      throw Error("pose check: a segment index is past the scan's " + std::to_string(scan.size()) +
                  " points");
  }
  const Eigen::Matrix3d R = T_S_O.linear();
  if (!T_S_O.matrix().allFinite() || !(R.transpose() * R).isIdentity(1e-9) ||
      !(R.determinant() > 0.0)) {
    throw Error(
        "pose check: T_S_O must be finite, a rotation (orthonormal, det +1) and a translation");
  }
  const std::size_t object = static_cast<std::size_t>(found - db.objects.begin());

  const PointCloud down = VoxelDownsample(scan, VoxelFilterOptions{db.parameters.voxel_m});
  const PlaneRemovalResult removed = RemoveSupportPlanes(down, db.LargestDiameter(), options);
  const KnnIndex down_index(down.points);
  std::map<std::string, double> untimed;
  recognition::StageClock clock(untimed);
  const recognition::ScanContext ctx{db, options, cache, down, down_index, removed.planes, clock};

  RecognitionCandidate unverified;
  unverified.object_id = object_id;
  unverified.T_S_O = T_S_O;
  const std::vector<std::size_t> voxels =
      SegmentInVoxels(scan, segment, down, down_index, removed.planes);
  if (voxels.size() < 10) return unverified;  // all on a support plane: nothing left to fit
  const PointCloud part = Subset(down, voxels);
  const SceneAround around = recognition::SceneAroundOf(part, ctx);
  const recognition::DescribedSegment described = recognition::DescribeSegment(part, ctx);
  // Verified as given, and refined as the pose search refines its best starts (the fine ICP on a
  // sample of the segment, then its last stage on every point), the better of the two: a pose
  // from outside may be off the scan by its noise, and ICP alone slides along what the scan
  // leaves free (a flange seen from its face drifted 2 cm along its axis from its true pose,
  // where it fit perfectly). Not sifted: the sift would also try the pose's half turns, and this
  // is about the pose given.
  const ObjectModel& model = db.objects[object];
  const ModelIndexes& indexes = cache.Model(object);
  const IcpOptions fine = FineIcp(model.diameter_m, db.parameters, options.threads);
  const PointCloud sample =
      recognition::Strided(described.cloud, static_cast<std::size_t>(options.refine_points));
  RegistrationResult refined = AlignIcp(sample, indexes.target, T_S_O.inverse(), fine);
  refined = AlignIcp(described.cloud, indexes.target, refined.T_target_source,
                     FineIcpLastStage(model.diameter_m, db.parameters, options.threads));
  RecognitionCandidate checked = unverified;
  recognition::Verify(described.cloud, model, indexes.nearest(), around, refined, ctx, checked);
  RegistrationResult as_given;
  as_given.T_target_source = T_S_O.inverse();
  as_given.fitness = FitnessAt(described.cloud, model, indexes.nearest(), T_S_O.inverse(),
                               fine.max_correspondence_distance_m.back());
  RecognitionCandidate given = unverified;
  recognition::Verify(described.cloud, model, indexes.nearest(), around, as_given, ctx, given);
  return recognition::Better(checked, given) ? checked : given;
}

}  // namespace uwscan::perception
