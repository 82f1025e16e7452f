#include "perception/recognition/object_recognizer.hpp"

#include <algorithm>
#include <deque>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <tuple>

#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/preprocessing/clustering.hpp"
#include "perception/preprocessing/normals.hpp"
#include "perception/preprocessing/plane_removal.hpp"
#include "perception/preprocessing/voxel_filter.hpp"
#include "perception/recognition/accepted_object.hpp"
#include "perception/recognition/object_database_builder.hpp"
#include "perception/recognition/object_pose_search.hpp"
#include "perception/recognition/object_symmetry.hpp"
#include "perception/recognition/recognition_verification.hpp"
#include "perception/recognition/residual_patches.hpp"
#include "perception/recognition/scan_segments.hpp"
#include "perception/recognition/segment_candidates.hpp"
#include "perception/recognition/segment_pose.hpp"
#include "perception/recognition/segment_split.hpp"
#include "perception/registration/coarse_alignment.hpp"
#include "perception/registration/icp.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/common/parallel_tasks.hpp"

namespace uwscan::perception {
namespace {

using namespace recognition;

// indices[i] for the positions i listed in `positions` (increasing), and for the others.
std::pair<std::vector<std::size_t>, std::vector<std::size_t>> Partition(
    const std::vector<std::size_t>& indices, const std::vector<std::size_t>& positions) {
  std::pair<std::vector<std::size_t>, std::vector<std::size_t>> split;
  std::size_t k = 0;
  for (std::size_t i = 0; i < indices.size(); ++i) {
    const bool listed = k < positions.size() && positions[k] == i;
    (listed ? split.first : split.second).push_back(indices[i]);
    k += listed ? 1 : 0;
  }
  return split;
}

// The smallest of `chi_square` other than object `o`'s (infinity when there is none).
double NearestOther(std::size_t o, const std::vector<double>& chi_square) {
  double other = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < chi_square.size(); ++i) {
    if (i != o) other = std::min(other, chi_square[i]);
  }
  return other;
}

// A segment waiting to be recognised: indices into the scan's points left after plane removal.
struct PendingSegment {
  std::vector<std::size_t> indices;
  double core_diameter_m = 0.0;
  int objects_before = 0;  // objects already taken out of the segment it came from
};

// Clusters of `indices` (into `cloud`) with at least min_segment_points, as pending segments.
void QueueClusters(const PointCloud& cloud, const std::vector<std::size_t>& indices,
                   int objects_before, const RecognitionOptions& options,
                   std::deque<PendingSegment>& pending) {
  if (indices.size() < static_cast<std::size_t>(options.min_segment_points)) return;
  const PointCloud rest = Subset(cloud, indices);
  ClusteringOptions clustering;
  clustering.tolerance_m = options.cluster_tolerance_m;
  for (const std::vector<std::size_t>& c : EuclideanClusters(rest, clustering)) {
    if (c.size() < static_cast<std::size_t>(options.min_segment_points)) continue;
    PendingSegment next{{}, Diameter(Subset(rest, c)), objects_before};
    for (std::size_t i : c) next.indices.push_back(indices[i]);
    pending.push_back(std::move(next));
  }
}

// What recognising one segment gives: its object (or "unknown"), the segment's points it keeps,
// and what it leaves unexplained, queued as segments of their own.
struct SegmentOutcome {
  RecognizedObject object;
  std::vector<std::size_t> kept;  // into the plane-free cloud
  std::deque<PendingSegment> queued;
};

// A segment being recognised, as the steps of RecognizeSegment see it.
struct SegmentInView {
  const PendingSegment& pending;
  const PointCloud& remaining;  // the plane-free cloud pending.indices index
  const PointCloud& cloud;      // the segment's points
  const SceneAround& around;
  const DescribedSegment& described;
};

// The segment before any object is accepted on it: unknown, keeping all its points.
SegmentOutcome Unrecognized(const SegmentInView& seg) {
  SegmentOutcome out;
  out.object.object_id = "unknown";
  out.object.centroid_S = Centroid(seg.cloud);
  out.kept = seg.pending.indices;
  return out;
}

// The highest score of a verified candidate among `posed`, -1 when none is verified.
double BestVerifiedScore(const std::vector<PosedObject>& posed) {
  double best = -1.0;
  for (const PosedObject& q : posed) {
    if (q.candidate.verified) best = std::max(best, q.candidate.score);
  }
  return best;
}

// The objects beyond the chosen worth posing: when the chosen explain the segment poorly (their
// best verified score `weak` is under weak_score) or not at all (weak < 0), the others may.
std::vector<std::size_t> OthersWorthPosing(const ChosenObjects& chosen, double weak,
                                           const RecognitionOptions& options) {
  if (weak < 0.0) return chosen.others_that_fit;
  return weak < options.weak_score ? chosen.others : std::vector<std::size_t>{};
}

// The segment's candidates posed and verified, the contenders placed along their free
// directions, best first.
std::vector<PosedObject> PoseAndRank(const SegmentInView& seg, const ChosenObjects& chosen,
                                     const ScanContext& ctx) {
  const RecognitionOptions& options = ctx.options;
  std::vector<PosedObject> posed;
  for (std::size_t i : chosen.objects) {
    posed.push_back(PoseCandidate(seg.described, i, chosen, seg.around, ctx));
  }
  const double weak = BestVerifiedScore(posed);
  RecognitionOptions others_options = options;
  if (weak < 0.0) others_options.pose_views = options.unverified_pose_views;
  const ScanContext others_ctx{ctx.db,         others_options, ctx.cache, ctx.down,
                               ctx.down_index, ctx.planes,     ctx.clock};
  for (std::size_t i : OthersWorthPosing(chosen, weak, options)) {
    posed.push_back(PoseCandidate(seg.described, i, chosen, seg.around, others_ctx));
  }
  PlaceContendersAlongFreeDirections(seg.described.cloud, seg.around, ctx, posed);
  ctx.clock.Lap("free");
  std::stable_sort(posed.begin(), posed.end(), [](const PosedObject& a, const PosedObject& b) {
    return Better(a.candidate, b.candidate);
  });
  BreakTie(options.score_tie, options.buried_depth_m, posed);
  return posed;
}

// The segment's points `best` leaves unexplained, which may be another object touching it, as
// segments of their own.
std::deque<PendingSegment> LeftUnexplained(const SegmentInView& seg, const PosedObject& best,
                                           const ScanContext& ctx) {
  const std::vector<std::size_t> on_model = PointsOnModel(
      seg.described.cloud, ctx.db.objects[best.object], ctx.cache.Model(best.object).nearest(),
      best.candidate.T_S_O.inverse(), 3.0 * ctx.db.parameters.voxel_m);
  const std::vector<std::size_t> rest = Partition(seg.pending.indices, on_model).second;
  std::deque<PendingSegment> queued;
  QueueClusters(seg.remaining, rest, seg.pending.objects_before + 1, ctx.options, queued);
  return queued;
}

// `indices` without those the `queued` segments took.
std::vector<std::size_t> WithoutQueued(std::vector<std::size_t> indices,
                                       const std::deque<PendingSegment>& queued) {
  std::vector<std::size_t> taken;
  for (const PendingSegment& q : queued) {
    taken.insert(taken.end(), q.indices.begin(), q.indices.end());
  }
  std::sort(taken.begin(), taken.end());
  std::erase_if(indices,
                [&](std::size_t i) { return std::binary_search(taken.begin(), taken.end(), i); });
  return indices;
}

// The best-ranked (verified) candidate accepted, with the other objects that fit as well and the
// poses as good as its own; with `split_allowed`, what it leaves unexplained is queued.
SegmentOutcome AcceptBest(const SegmentInView& seg, const std::vector<PosedObject>& ranked,
                          const std::vector<double>& nearest_chi_square, bool split_allowed,
                          const ScanContext& ctx) {
  SegmentOutcome out = Unrecognized(seg);
  const PosedObject& best = ranked.front();
  Accept(best, seg.described.cloud, ctx.db.objects[best.object],
         NearestOther(best.object, nearest_chi_square), ctx, out.object);
  // The others that fit as well, as posed by the same search and placed as the answer is.
  out.object.equivalent_objects_S = EquivalentObjects(ranked, ctx.options.score_tie);
  out.object.equivalent_poses_S = EquivalentPoses(seg.described, best, seg.around, ctx);
  ctx.clock.Lap("equivalents");
  if (split_allowed) {
    out.queued = LeftUnexplained(seg, best, ctx);
    out.kept = WithoutQueued(seg.pending.indices, out.queued);
  }
  return out;
}

// The chi-square of the part's ESF to every object's nearest view, with the posed object's
// chi-square and view set from it; none when the part has no ESF.
std::vector<double> PartChiSquares(const EsfResult& part_esf, const ObjectDatabase& db,
                                   PosedObject& posed) {
  std::vector<double> chi_square;
  if (!part_esf.ok) return chi_square;
  for (const auto& nearest : NearestViews(part_esf.histogram, db, 1)) {
    chi_square.push_back(nearest.front().first);
    if (chi_square.size() == posed.object + 1) posed.candidate.view = nearest.front().second;
  }
  posed.candidate.chi_square = chi_square[posed.object];
  return chi_square;
}

// With no candidate verified, the part of the segment one object explains (ExplainPart) accepted
// as its object, and the rest queued as segments of their own; unrecognised when there is none.
SegmentOutcome SplitOffPart(const SegmentInView& seg, const ScanContext& ctx) {
  SegmentOutcome out = Unrecognized(seg);
  std::optional<ExplainedPart> part = ExplainPart(seg.described, ctx);
  ctx.clock.Lap("split");
  if (!part) return out;
  const RecognitionOptions& options = ctx.options;
  const PointCloud part_cloud = Subset(seg.cloud, part->points);
  // The part's own ESF for its chi-square and margin.
  const EsfResult part_esf =
      VoxelisedEsf(part_cloud, ctx.db.parameters.voxel_m, options.seed, options.threads);
  const std::vector<double> part_chi_square = PartChiSquares(part_esf, ctx.db, part->posed);
  // On the part's points with their normals (the fine ICP's normal gate needs them).
  const PointCloud part_described = Subset(seg.described.cloud, part->points);
  PlaceAlongFreeDirections(part_described, SceneAroundOf(part_cloud, ctx), ctx, part->posed);
  out.object.candidates.push_back(part->posed.candidate);
  Accept(part->posed, part_described, ctx.db.objects[part->posed.object],
         part_esf.ok ? NearestOther(part->posed.object, part_chi_square) : 0.0, ctx, out.object);
  out.object.centroid_S = Centroid(part_cloud);
  std::vector<std::size_t> rest;
  std::tie(out.kept, rest) = Partition(seg.pending.indices, part->points);
  QueueClusters(seg.remaining, rest, seg.pending.objects_before + 1, options, out.queued);
  return out;
}

// A described segment recognised from its ESF: the objects it resembles posed, verified and
// ranked, and the best accepted or, when none is verified, the part one object explains split
// off it. Every ranked candidate is listed, after the part's.
SegmentOutcome RecognizeDescribed(const SegmentInView& seg, const EsfDescriptor& esf,
                                  const ScanContext& ctx) {
  const RecognitionOptions& options = ctx.options;
  const ChosenObjects chosen = ChooseObjects(esf, seg.pending.core_diameter_m, ctx);
  ctx.clock.Lap("match");
  const std::vector<PosedObject> ranked = PoseAndRank(seg, chosen, ctx);
  const bool split_allowed = seg.pending.objects_before + 1 < options.max_objects_per_segment;
  SegmentOutcome out;
  if (!ranked.empty() && ranked.front().candidate.verified) {
    out = AcceptBest(seg, ranked, chosen.nearest_chi_square, split_allowed, ctx);
  } else if (split_allowed &&
             seg.cloud.size() >= 2 * static_cast<std::size_t>(options.min_segment_points)) {
    out = SplitOffPart(seg, ctx);
  } else {
    out = Unrecognized(seg);
  }
  for (const PosedObject& c : ranked) out.object.candidates.push_back(c.candidate);
  return out;
}

// One segment of the plane-free cloud `remaining` recognised: its candidates posed and verified,
// the best accepted, or, when none is verified, the part one object explains split off it.
SegmentOutcome RecognizeSegment(const PendingSegment& next, const PointCloud& remaining,
                                const ScanContext& ctx) {
  const PointCloud segment = Subset(remaining, next.indices);
  const SceneAround around = SceneAroundOf(segment, ctx);
  const DescribedSegment described = DescribeSegment(segment, ctx);
  const SegmentInView seg{next, remaining, segment, around, described};
  const EsfResult esf =
      VoxelisedEsf(segment, ctx.db.parameters.voxel_m, ctx.options.seed, ctx.options.threads);
  ctx.clock.Lap("describe");
  SegmentOutcome out = esf.ok && described.cloud.size() >= 10
                           ? RecognizeDescribed(seg, esf.histogram, ctx)
                           : Unrecognized(seg);
  ctx.clock.Lap("verify");
  return out;
}

// The database index of the object named `id`.
std::size_t ObjectIndex(const ObjectDatabase& db, const std::string& id) {
  for (std::size_t i = 0; i < db.objects.size(); ++i) {
    if (db.objects[i].id == id) return i;
  }
  throw Error("recognition: no object '" + id + "' in the database");  // answers come from it
}

// Whether `object` (posed as `T_S_O`) has at least `share` of `part`'s points (indices into
// `remaining`) within 1.5 voxels of its model.
bool ExplainsPart(const PointCloud& remaining, const std::vector<std::size_t>& part,
                  std::size_t object, const Eigen::Isometry3d& T_S_O, double share,
                  const ScanContext& ctx) {
  const PointCloud cloud = Subset(remaining, part);
  const std::size_t on =
      PointsOnModel(cloud, ctx.db.objects[object], ctx.cache.Model(object).nearest(),
                    T_S_O.inverse(), 1.5 * ctx.db.parameters.voxel_m)
          .size();
  return static_cast<double>(on) >= share * static_cast<double>(cloud.size());
}

// Whether segments `a` and `b` are worth recognising as one: a segment no object explains next to
// a recognised one (a handwheel its own shadow cut off from its valve's body, when the body also
// touched another object and so could not join it in Segments), two answered as the same object
// (the handwheel alone fits the wheel valve too, badly), or two of which one is explained poorly
// (scoring under `weak_score`: a split that gave most of a flange to a tee, which fit it with a
// sixth of its model in the seabed, and the rest to the flange). Pairs of recognised segments are
// taken once (a < b).
bool WorthJoining(const RecognizedObject& a, const RecognizedObject& b, std::size_t ia,
                  std::size_t ib, double weak_score) {
  if (a.object_id == "unknown") return b.object_id != "unknown";
  if (b.object_id == "unknown" || ib < ia) return false;
  return b.object_id == a.object_id || a.score < weak_score || b.score < weak_score;
}

// Segment `k` joined with the nearest other WorthJoining it (see JoinSegmentsOneObjectExplains):
// the entry that holds the union (the pair's first; the second is dropped), or none.
std::optional<std::size_t> JoinNearest(const PointCloud& remaining, double largest_object_m,
                                       const ScanContext& ctx, std::size_t k,
                                       std::vector<bool>& dropped,
                                       std::vector<RecognizedObject>& objects,
                                       std::vector<std::vector<std::size_t>>& points) {
  if (dropped[k] || points[k].empty()) return std::nullopt;
  std::vector<Segment> others(objects.size());
  for (std::size_t j = 0; j < objects.size(); ++j) {
    if (j != k && !dropped[j] &&
        WorthJoining(objects[k], objects[j], k, j, ctx.options.weak_score)) {
      others[j].indices = points[j];
    }
  }
  const auto [to, distance] = NearestSegment(remaining, points[k], others, k);
  if (distance > ctx.options.attach_distance_m) return std::nullopt;
  std::vector<std::size_t> both = points[k];
  both.insert(both.end(), points[to].begin(), points[to].end());
  std::sort(both.begin(), both.end());
  const double diameter = Diameter(Subset(remaining, both));
  if (diameter > largest_object_m) return std::nullopt;
  SegmentOutcome joined =
      RecognizeSegment({both, diameter, ctx.options.max_objects_per_segment - 1}, remaining, ctx);
  if (joined.object.object_id == "unknown") return std::nullopt;
  const double apart = (objects[k].score * static_cast<double>(points[k].size()) +
                        objects[to].score * static_cast<double>(points[to].size())) /
                       static_cast<double>(both.size());
  if (joined.object.score < apart) return std::nullopt;
  const std::size_t object = ObjectIndex(ctx.db, joined.object.object_id);
  const double share = ctx.options.min_fitness;
  if (!ExplainsPart(remaining, points[k], object, joined.object.T_S_O, share, ctx) ||
      !ExplainsPart(remaining, points[to], object, joined.object.T_S_O, share, ctx)) {
    return std::nullopt;
  }
  const std::size_t first = std::min(k, to), second = std::max(k, to);
  objects[first] = std::move(joined.object);
  points[first] = std::move(joined.kept);
  points[second].clear();
  dropped[second] = true;
  return first;
}

// Segments that one object explains better together than apart, joined after the per-segment
// pass: for each segment, the nearest other within attach_distance_m WorthJoining it is
// recognised with it as one segment (not split again) when together they are no wider than the
// largest object. The union replaces the pair when it is verified, its object puts min_fitness
// of each one's points on its model, and it scores at least their scores' mean weighted by points
// (an unknown one's counting 0): a wheel valve whose handwheel was cut off then comes out whole
// and posed where its body alone fitted the lever valve as well. `objects` and `points` (indices
// into `remaining`) stay in order, the pair's second entry dropped.
void JoinSegmentsOneObjectExplains(const PointCloud& remaining, double largest_object_m,
                                   const ScanContext& ctx, std::vector<RecognizedObject>& objects,
                                   std::vector<std::vector<std::size_t>>& points) {
  // The stages of the segments recognised here are timed as one, "join".
  std::map<std::string, double> untimed;
  StageClock clock(untimed);
  const ScanContext join_ctx{ctx.db,         ctx.options, ctx.cache, ctx.down,
                             ctx.down_index, ctx.planes,  clock};
  std::vector<bool> dropped(objects.size(), false);
  std::size_t k = 0;
  while (k < objects.size()) {
    const std::optional<std::size_t> into =
        JoinNearest(remaining, largest_object_m, join_ctx, k, dropped, objects, points);
    if (into != k) ++k;  // else the grown segment may join another
  }
  std::size_t kept = 0;
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (dropped[i]) continue;
    if (kept != i) {  // a self-move would empty them
      objects[kept] = std::move(objects[i]);
      points[kept] = std::move(points[i]);
    }
    ++kept;
  }
  objects.resize(kept);
  points.resize(kept);
}

}  // namespace

void RecognitionOptions::Check() const {
  const OptionChecks check("RecognitionOptions");
  check.Positive("plane_distance_m", plane_distance_m, "m");
  check.InRange("plane_min_fraction", plane_min_fraction, 0.0, 1.0, Interval::kOpenLow);
  check.Positive("cluster_tolerance_m", cluster_tolerance_m, "m");
  check.NonNegative("attach_distance_m", attach_distance_m, "m");
  check.AtLeast("min_segment_points", min_segment_points, 10);
  check.AtLeast("max_candidates", max_candidates, 1);
  check.InRange("pose_views", pose_views, 0, 64);
  check.InRange("unverified_pose_views", unverified_pose_views, 0, 64);
  check.InRange("pose_rolls", pose_rolls, 1, 360);
  check.InRange("sift_points", sift_points, 10, 100000);
  check.InRange("refined_starts", refined_starts, 1, 64);
  check.InRange("refine_points", refine_points, 10, 10000000);
  check.Positive("max_chi_square", max_chi_square);
  check.AtLeast("max_chi_square_ratio", max_chi_square_ratio, 1.0);
  check.InRange("min_fitness", min_fitness, 0.0, 1.0);
  check.InRange("min_close", min_close, 0.0, 1.0);
  check.InRange("max_missing", max_missing, 0.0, 1.0);
  check.InRange("min_part_share", min_part_share, 0.0, 1.0);
  check.InRange("weak_score", weak_score, 0.0, 1.0);
  check.AtLeast("max_objects_per_segment", max_objects_per_segment, 1);
  check.AtLeast("split_candidates", split_candidates, 1);
  check.Positive("close_distance_m", close_distance_m, "m");
  check.Positive("free_direction_std_m", free_direction_std_m, "m");
  check.Positive("residual_patch_m", residual_patch_m, "m");
  check.NonNegative("buried_depth_m", buried_depth_m, "m");
  check.NonNegative("pose_floor_std_m", pose_floor_std_m, "m");
  check.NonNegative("pose_restart_voxels", pose_restart_voxels, "voxels");
  check.NonNegative("min_phase_points", min_phase_points);
  check.AtLeast("threads", threads, 0);
}

RecognitionResult RecognizeObjects(const PointCloud& scan, const ObjectDatabase& db,
                                   const RecognitionOptions& options) {
  RecognitionCache cache(db);
  return RecognizeObjects(scan, db, cache, options);
}

RecognitionResult RecognizeObjects(const PointCloud& scan, const ObjectDatabase& db,
                                   RecognitionCache& cache, const RecognitionOptions& options) {
  options.Check();
  if (&cache.db() != &db)
    throw Error("recognition: the RecognitionCache was made for another object database");
  RequireValidCloud(scan, "scan", 1);
  if (db.objects.empty()) throw Error("recognition: the object database is empty");
  const ObjectDatabaseParameters& p = db.parameters;
  RecognitionResult result;
  StageClock clock(result.stage_seconds);

  const PointCloud down = VoxelDownsample(scan, VoxelFilterOptions{p.voxel_m});
  const double largest_object_m = db.LargestDiameter();
  const PlaneRemovalResult removed = RemoveSupportPlanes(down, largest_object_m, options);
  for (const DetectedPlane& plane : removed.planes) result.plane_points += plane.inliers.size();
  clock.Lap("preprocess");

  std::deque<PendingSegment> pending;
  for (Segment& s : Segments(removed.remaining, largest_object_m, options))
    pending.push_back({std::move(s.indices), s.core_diameter_m, 0});
  clock.Lap("segment");

  const KnnIndex down_index(down.points);
  const ScanContext ctx{db, options, cache, down, down_index, removed.planes, clock};
  std::vector<std::vector<std::size_t>> object_points;  // per object, into removed.remaining
  while (!pending.empty()) {
    SegmentOutcome outcome = RecognizeSegment(pending.front(), removed.remaining, ctx);
    pending.pop_front();
    for (PendingSegment& q : outcome.queued) pending.push_back(std::move(q));
    object_points.push_back(std::move(outcome.kept));
    result.objects.push_back(std::move(outcome.object));
  }
  JoinSegmentsOneObjectExplains(removed.remaining, largest_object_m, ctx, result.objects,
                                object_points);
  clock.Lap("join");

  // Every scan point goes to the object of the voxel point nearest to it.
  std::vector<int> object_of_down(down.size(), -1);
  for (std::size_t k = 0; k < object_points.size(); ++k) {
    for (std::size_t i : object_points[k])
      object_of_down[removed.remaining_indices[i]] = static_cast<int>(k);
  }
  if (!object_points.empty()) {
    std::vector<std::uint32_t> nearest;
    std::vector<float> squared;
    const Eigen::Vector3f shift = (scan.origin - down.origin).cast<float>();
    for (std::size_t i = 0; i < scan.size(); ++i) {
      down_index.Query(scan.points[i] + shift, 1, nearest, squared);
      const int k = object_of_down[nearest[0]];
      if (k >= 0) result.objects[static_cast<std::size_t>(k)].segment.push_back(i);
    }
  }
  clock.Lap("segment");
  return result;
}

}  // namespace uwscan::perception
