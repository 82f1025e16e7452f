#include "perception/recognition/segment_split.hpp"

#include <Eigen/Eigenvalues>
#include <array>

#include "perception/recognition/object_database_builder.hpp"
#include "perception/recognition/object_pose_search.hpp"
#include "perception/recognition/segment_candidates.hpp"
#include "perception/registration/icp.hpp"
#include "scanner/common/parallel_tasks.hpp"

namespace uwscan::perception::recognition {
namespace {

// The two halves of a cloud split across one of its principal axes (0 the longest) by 2-means,
// started from its two extreme points along that axis: touching objects mostly end up one in
// each, across the longest axis when they lie end to end, across the next when side by side.
std::array<std::vector<std::size_t>, 2> Halves(const PointCloud& cloud, int principal_axis) {
  const Eigen::Vector3d mean = Centroid(cloud);
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < cloud.size(); ++i)
    scatter += (cloud.Point(i) - mean) * (cloud.Point(i) - mean).transpose();
  const Eigen::Vector3d axis =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(2 -
                                                                                 principal_axis);
  std::size_t lo = 0, hi = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (cloud.Point(i).dot(axis) < cloud.Point(lo).dot(axis)) lo = i;
    if (cloud.Point(i).dot(axis) > cloud.Point(hi).dot(axis)) hi = i;
  }
  std::array<Eigen::Vector3d, 2> centre = {cloud.Point(lo), cloud.Point(hi)};
  std::array<std::vector<std::size_t>, 2> halves;
  for (int iteration = 0; iteration < 20; ++iteration) {
    std::array<std::vector<std::size_t>, 2> next;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Eigen::Vector3d x = cloud.Point(i);
      next[(x - centre[1]).squaredNorm() < (x - centre[0]).squaredNorm() ? 1 : 0].push_back(i);
    }
    if (next == halves) break;
    halves = std::move(next);
    for (int h = 0; h < 2; ++h) {
      if (halves[h].empty()) continue;
      centre[h].setZero();
      for (std::size_t i : halves[h]) centre[h] += cloud.Point(i);
      centre[h] /= static_cast<double>(halves[h].size());
    }
  }
  return halves;
}

// A half of a segment recognised as a segment of its own, for pose candidates (ExplainPart).
struct DescribedHalf {
  DescribedSegment described;
  SceneAround around;
  ChosenObjects chosen;
};

// The halves of a segment worth recognising: Halves across its two longest principal axes,
// distinct, with min_segment_points and an ESF.
std::vector<DescribedHalf> DescribedHalves(const DescribedSegment& s, const ScanContext& ctx) {
  const ObjectDatabaseParameters& p = ctx.db.parameters;
  std::vector<std::vector<std::size_t>> halves;
  for (int axis = 0; axis < 2; ++axis) {
    for (std::vector<std::size_t>& half : Halves(s.cloud, axis)) {
      if (half.size() < static_cast<std::size_t>(ctx.options.min_segment_points)) continue;
      if (std::find(halves.begin(), halves.end(), half) == halves.end())
        halves.push_back(std::move(half));
    }
  }
  std::vector<std::optional<DescribedHalf>> described(halves.size());
  RunParallelTasks(std::ssize(halves), ctx.options.threads, [&](std::ptrdiff_t h) {
    const PointCloud half_cloud = Subset(s.cloud, halves[static_cast<std::size_t>(h)]);
    const EsfResult esf =
        VoxelisedEsf(half_cloud, p.voxel_m, ctx.options.seed, 1);  // one task per thread
    if (!esf.ok) return;
    const OneThreadContext task(ctx);
    described[static_cast<std::size_t>(h)].emplace(
        DescribedHalf{{half_cloud, DescribeSegment(half_cloud, task.ctx()).features},
                      SceneAroundOf(half_cloud, task.ctx()),
                      ChooseObjects(esf.histogram, Diameter(half_cloud), task.ctx())});
  });
  std::vector<DescribedHalf> kept;
  for (std::optional<DescribedHalf>& d : described) {
    if (d) kept.push_back(std::move(*d));
  }
  return kept;
}

// Object `object`, posed on a half of segment `s`, as the part of `s` it explains: from its pose
// the trimmed fine ICP of the whole segment leaves the other objects' points out, and the points
// it puts on the model form the part, posed again and verified on its own. None when the part is
// under min_part_share of the segment, or not verified.
std::optional<ExplainedPart> PartOnHalf(const DescribedSegment& s, const PointCloud& sample,
                                        const DescribedHalf& half, std::size_t object,
                                        const ScanContext& ctx) {
  const ObjectDatabaseParameters& p = ctx.db.parameters;
  const ObjectModel& model = ctx.db.objects[object];
  const PosedObject posed = PoseCandidate(half.described, object, half.chosen, half.around, ctx);
  const ModelIndexes& indexes = ctx.cache.Model(object);
  const IcpOptions fine = FineIcp(model.diameter_m, p, ctx.options.threads);
  const RegistrationResult on_segment =
      AlignIcp(sample, indexes.target, posed.fine.T_target_source, fine);
  std::vector<std::size_t> points =
      PointsOnModel(s.cloud, model, indexes.nearest(), on_segment.T_target_source, 1.5 * p.voxel_m);
  const double share = static_cast<double>(points.size()) / static_cast<double>(s.cloud.size());
  if (share < ctx.options.min_part_share ||
      points.size() < static_cast<std::size_t>(ctx.options.min_segment_points)) {
    return std::nullopt;
  }
  const PointCloud part = Subset(s.cloud, points);
  const RegistrationResult refined =
      AlignIcp(part, indexes.target, on_segment.T_target_source, fine);
  const SceneAround around = SceneAroundOf(part, ctx);
  ExplainedPart candidate{posed, std::move(points), share};
  candidate.posed.fine = refined;
  Verify(part, model, indexes.nearest(), around, refined, ctx, candidate.posed.candidate);
  if (!candidate.posed.candidate.verified) return std::nullopt;
  return candidate;
}

}  // namespace

std::optional<ExplainedPart> ExplainPart(const DescribedSegment& s, const ScanContext& ctx) {
  const PointCloud sample = Strided(s.cloud, static_cast<std::size_t>(ctx.options.refine_points));
  const std::vector<DescribedHalf> halves = DescribedHalves(s, ctx);
  std::vector<std::pair<std::size_t, std::size_t>> tasks;  // (half, object)
  for (std::size_t h = 0; h < halves.size(); ++h) {
    const std::vector<std::size_t>& objects = halves[h].chosen.objects;
    const std::size_t count =
        std::min(objects.size(), static_cast<std::size_t>(ctx.options.split_candidates));
    for (std::size_t k = 0; k < count; ++k) tasks.emplace_back(h, objects[k]);
  }
  std::vector<std::optional<ExplainedPart>> parts(tasks.size());
  RunParallelTasks(std::ssize(tasks), ctx.options.threads, [&](std::ptrdiff_t t) {
    const auto [h, object] = tasks[static_cast<std::size_t>(t)];
    const OneThreadContext task(ctx);
    parts[static_cast<std::size_t>(t)] = PartOnHalf(s, sample, halves[h], object, task.ctx());
  });
  std::optional<ExplainedPart> best;
  for (std::optional<ExplainedPart>& part : parts) {
    if (!part) continue;
    if (!best ||
        part->share * part->posed.candidate.score > best->share * best->posed.candidate.score) {
      best = std::move(part);
    }
  }
  return best;
}

}  // namespace uwscan::perception::recognition
