#include "perception/recognition/segment_pose.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "perception/preprocessing/normals.hpp"
#include "perception/recognition/free_directions.hpp"
#include "perception/recognition/object_symmetry.hpp"
#include "scanner/common/parallel_tasks.hpp"

namespace uwscan::perception::recognition {
namespace {

// Inliers a removed plane needs within the largest object's diameter of a segment to count as
// its support: a few voxels' worth of seabed or wall beside it.
constexpr std::size_t kSupportPoints = 20;

// The pose's phase about each N-fold axis of the model (SymmetryPhaseStarts): details repeating
// about an axis (a flange's bolts) are out of the ICP's reach when off, and the verification's
// score barely sees them, so a phase the search found stands unless it scores clearly worse than
// the pose it turned; of two, the better scoring.
void SearchSymmetryPhases(const DescribedSegment& s, const PointCloud& sample,
                          const ObjectModel& model, const IcpTarget& target,
                          const NearestGrid& model_grid, const IcpOptions& fine,
                          const SceneAround& around, const ScanContext& ctx, PosedObject& best) {
  for (const SymmetryAxis& axis : model.symmetries) {
    const PosedObject before = best;
    bool turned_once = false;
    // Scored on every segment point, not the ICP's sample: the bolt heads are a few percent of
    // the segment, and a sample of 1000 points keeps a handful of them.
    for (const Eigen::Isometry3d& turned :
         SymmetryPhaseStarts(s.cloud, model, model_grid, axis, before.fine.T_target_source,
                             ctx.db.parameters.voxel_m)) {
      const RegistrationResult refined = AlignIcp(sample, target, turned, fine);
      RecognitionCandidate c = before.candidate;
      Verify(s.cloud, model, model_grid, around, refined, ctx, c);
      if (c.verified < before.candidate.verified ||
          c.score < before.candidate.score - ctx.options.score_tie)
        continue;
      if (turned_once && !Better(c, best.candidate)) continue;
      turned_once = true;
      best.candidate = c;
      best.fine = refined;
    }
  }
}

// Share of the model's points (every 4th) that `turn` (T_O_O') puts within a voxel of the model.
double SelfOverlap(const ObjectModel& model, const NearestGrid& model_grid,
                   const Eigen::Isometry3d& turn, double voxel_m) {
  std::size_t on = 0, count = 0;
  for (std::size_t i = 0; i < model.model.size(); i += 4, ++count) {
    const Eigen::Vector3d x = turn * model.model.Point(i);
    on += model_grid.Nearest((x - model.model.origin).cast<float>(),
                             static_cast<float>(voxel_m * voxel_m)) >= 0
              ? 1
              : 0;
  }
  return count == 0 ? 0.0 : static_cast<double>(on) / static_cast<double>(count);
}

// Half turns of a model (T_O_O') about its principal axes and about its own frame's axes through
// its origin (a procedural object's stem or run: a valve's lever tilts the principal axes off
// its stem), and about the bisectors of two frame axes when such a turn lays at least half the
// model back on itself (a tee seen as an L, its run's one half and its branch, fits turned about
// their bisector); without those that are its symmetries or repeat another (within 5 degrees
// and 2 voxels at its centre): they would end where they started.
std::vector<Eigen::Isometry3d> DistinctHalfTurns(const ObjectModel& model,
                                                 const NearestGrid& model_grid, double voxel_m) {
  std::vector<Eigen::Isometry3d> candidates = HalfTurns(model.model);
  for (int axis = 0; axis < 3; ++axis) {
    candidates.emplace_back(Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::Unit(axis)));
  }
  for (int a = 0; a < 3; ++a) {
    for (int b = a + 1; b < 3; ++b) {
      for (double sign : {1.0, -1.0}) {
        const Eigen::Vector3d bisector =
            (Eigen::Vector3d::Unit(a) + sign * Eigen::Vector3d::Unit(b)).normalized();
        const Eigen::Isometry3d turn(Eigen::AngleAxisd(std::numbers::pi, bisector));
        if (SelfOverlap(model, model_grid, turn, voxel_m) >= 0.5) candidates.push_back(turn);
      }
    }
  }
  const Eigen::Vector3d centre_O = model.model.origin;
  auto alike = [&](const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
    const Eigen::Isometry3d d = a.inverse() * b;
    return Eigen::AngleAxisd(d.linear()).angle() < 5.0 * std::numbers::pi / 180.0 &&
           (d * centre_O - centre_O).norm() < 2.0 * voxel_m;
  };
  std::vector<Eigen::Isometry3d> known = SymmetryTransforms(model.symmetries);
  std::vector<Eigen::Isometry3d> turns;
  for (const Eigen::Isometry3d& turn : candidates) {
    if (std::any_of(known.begin(), known.end(),
                    [&](const Eigen::Isometry3d& k) { return alike(k, turn); }))
      continue;
    turns.push_back(turn);
    known.push_back(turn);
  }
  return turns;
}

// `posed` turned by each of DistinctHalfTurns, each refined by the fine ICP on a sample of
// `segment` (one turn per thread) and verified on all of it.
std::vector<PosedObject> HalfTurnedPoses(const PointCloud& segment, const PosedObject& posed,
                                         const SceneAround& around, const ScanContext& ctx) {
  const ObjectModel& model = ctx.db.objects[posed.object];
  const ObjectDatabaseParameters& p = ctx.db.parameters;
  const ModelIndexes& indexes = ctx.cache.Model(posed.object);
  const PointCloud sample = Strided(segment, static_cast<std::size_t>(ctx.options.refine_points));
  const std::vector<Eigen::Isometry3d> turns =
      DistinctHalfTurns(model, indexes.nearest(), p.voxel_m);
  std::vector<PosedObject> turned(turns.size(), posed);
  RunParallelTasks(std::ssize(turns), ctx.options.threads, [&](std::ptrdiff_t k) {
    PosedObject& t = turned[static_cast<std::size_t>(k)];
    t.fine = AlignIcp(sample, indexes.target,
                      turns[static_cast<std::size_t>(k)] * posed.fine.T_target_source,
                      FineIcp(model.diameter_m, p, 1));
    Verify(segment, model, indexes.nearest(), around, t.fine, ctx, t.candidate);
  });
  return turned;
}

}  // namespace

DescribedSegment DescribeSegment(const PointCloud& segment, const ScanContext& ctx) {
  NormalOptions normal_options;
  normal_options.radius_m = ctx.db.parameters.normal_radius_m;
  normal_options.threads = ctx.options.threads;
  DescribedSegment d;
  d.cloud = AttachNormals(segment, EstimateNormals(segment, normal_options)).cloud;
  std::vector<std::size_t> all(d.cloud.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  d.features = ComputeFpfh(d.cloud, all,
                           FpfhOptions{ctx.db.parameters.feature_radius_m, ctx.options.threads});
  return d;
}

SceneAround SceneAroundOf(const PointCloud& segment, const ScanContext& ctx) {
  SceneAround around =
      SceneAroundSegment(ctx.down, ctx.down_index, segment, 2.0 * ctx.db.parameters.voxel_m,
                         0.5 * ctx.db.LargestDiameter());
  // SceneAroundSegment refused an empty segment.
  around.support_planes = SupportPlanesAround(ctx.down, ctx.planes, Centroid(segment),
                                              ctx.db.LargestDiameter(), kSupportPoints);
  return around;
}

// The posed model verified on `segment`: fit, closeness, missing surface and support contact.
void Verify(const PointCloud& segment, const ObjectModel& model, const NearestGrid& model_grid,
            const SceneAround& around, const RegistrationResult& refined, const ScanContext& ctx,
            RecognitionCandidate& c) {
  const ObjectDatabaseParameters& p = ctx.db.parameters;
  const Eigen::Isometry3d T_O_S = refined.T_target_source;
  c.T_S_O = T_O_S.inverse();
  c.fitness = refined.fitness;
  c.rmse_m = refined.inlier_plane_rmse;
  c.missing = MissingShare(model, c.T_S_O, around, 2.0 * p.voxel_m);
  c.close = CloseShare(model.model, model_grid, Transformed(segment, T_O_S),
                       ctx.options.close_distance_m, p.voxel_m);
  const SupportContact contact =
      SupportContactOf(model, c.T_S_O, around.support_planes, ctx.options.buried_depth_m);
  c.buried = contact.buried;
  c.clearance_m = contact.clearance_m;
  c.score = c.close * (1.0 - c.missing) * (1.0 - c.buried);
  c.verified = c.fitness >= ctx.options.min_fitness && c.close >= ctx.options.min_close &&
               c.missing <= ctx.options.max_missing;
}

// Verified beats unverified, then the higher score; ties keep the earlier.
bool Better(const RecognitionCandidate& a, const RecognitionCandidate& b) {
  if (a.verified != b.verified) return a.verified;
  return a.score > b.score;
}

// Every k-th point of a cloud, at most about `count` of them.
PointCloud Strided(const PointCloud& cloud, std::size_t count) {
  const std::size_t stride = std::max<std::size_t>(1, (cloud.size() + count - 1) / count);
  std::vector<std::size_t> every;
  for (std::size_t i = 0; i < cloud.size(); i += stride) every.push_back(i);
  return Subset(cloud, every);
}

// An object's best pose on the whole segment from `starts`: sifted, the best few refined by the
// fine ICP on refine_points of the segment's points and verified on all of them; the winner's
// phase about any N-fold axis is searched, then it is refined once more on all its points (the
// pose barely moves, but its information is that of every point) and verified again.
PosedObject PoseOnSegment(const DescribedSegment& s, std::size_t object,
                          const std::vector<Eigen::Isometry3d>& starts, const SceneAround& around,
                          const ScanContext& ctx) {
  const ObjectModel& model = ctx.db.objects[object];
  const ObjectDatabaseParameters& p = ctx.db.parameters;
  const ModelIndexes& indexes = ctx.cache.Model(object);
  const IcpTarget& target = indexes.target;
  const NearestGrid& model_grid = indexes.nearest();
  const std::vector<Eigen::Isometry3d> sifted =
      SiftStarts(s.cloud, target, starts, model.diameter_m, p, ctx.options);
  ctx.clock.Lap("sift");
  const IcpOptions fine = FineIcp(model.diameter_m, p, ctx.options.threads);
  const PointCloud sample = Strided(s.cloud, static_cast<std::size_t>(ctx.options.refine_points));
  PosedObject best{object, {}, {}};
  bool posed = false;
  // The sift's short ICP ended at two voxels: the fine ICP goes on from there. One start per
  // thread: an ICP's own parallel loops over a thousand points are too short to pay.
  IcpOptions from_sift = fine;
  from_sift.max_correspondence_distance_m.erase(from_sift.max_correspondence_distance_m.begin());
  from_sift.threads = 1;
  std::vector<RegistrationResult> refined(sifted.size());
  std::vector<RecognitionCandidate> checked(sifted.size());
  RunParallelTasks(std::ssize(sifted), ctx.options.threads, [&](std::ptrdiff_t k) {
    const std::size_t i = static_cast<std::size_t>(k);
    refined[i] = AlignIcp(sample, target, sifted[i], from_sift);
    Verify(s.cloud, model, model_grid, around, refined[i], ctx, checked[i]);
  });
  for (std::size_t i = 0; i < sifted.size(); ++i) {
    if (posed && !Better(checked[i], best.candidate)) continue;
    posed = true;
    best.candidate = checked[i];
    best.fine = refined[i];
  }
  if (posed) {
    SearchSymmetryPhases(s, sample, model, target, model_grid, fine, around, ctx, best);
    ctx.clock.Lap("refine");
    // The pose has converged on the sample: the last stage alone, on every point, for the
    // information of them all (the coarser stages took 34 iterations on average to get back).
    best.fine = AlignIcp(s.cloud, target, best.fine.T_target_source,
                         FineIcpLastStage(model.diameter_m, p, ctx.options.threads));
    Verify(s.cloud, model, model_grid, around, best.fine, ctx, best.candidate);
  }
  ctx.clock.Lap("final");
  return best;
}

// What a posed model leaves unexplained, in points: model surface the sensor saw through, and
// segment points off the model's surface (CloseShare's test).
double Unexplained(const PointCloud& segment, const ObjectModel& model,
                   const NearestGrid& model_grid, const SceneAround& around,
                   const Eigen::Isometry3d& T_O_S, const ScanContext& ctx) {
  const double voxel_m = ctx.db.parameters.voxel_m;
  const SurfaceEvidence surface = ExpectedSurface(model, T_O_S.inverse(), around, 2.0 * voxel_m);
  const double close = CloseShare(model.model, model_grid, Transformed(segment, T_O_S),
                                  ctx.options.close_distance_m, voxel_m);
  return static_cast<double>(surface.missing) + (1.0 - close) * static_cast<double>(segment.size());
}

// The offset (metres) minimising `cost` over centre_m +- reach_m at steps of `step_m`, the
// profile smoothed over three neighbouring steps (a single offset can dip by chance, where a slide
// is really pinned the cost rises on both sides over several steps) and refined by a parabola
// through the smoothed minimum and its neighbours; with the smoothed gain over the centre. Ties go
// to the offset nearest the centre. The offsets are costed on `threads` threads.
struct SlideMinimum {
  double offset_m = 0.0;
  double gain = 0.0;
};
template <typename Cost>
SlideMinimum SmoothedMinimum(const Cost& cost, double centre_m, double step_m, double reach_m,
                             int threads) {
  const int steps = static_cast<int>(std::ceil(reach_m / step_m));
  const int n = 2 * steps + 1;
  std::vector<double> raw(static_cast<std::size_t>(n));
  RunParallelTasks(n, threads, [&](std::ptrdiff_t k) {
    raw[static_cast<std::size_t>(k)] = cost(centre_m + static_cast<double>(k - steps) * step_m);
  });
  std::vector<double> smooth(raw.size());
  for (int k = 0; k < n; ++k) {
    double sum = 0.0;
    int count = 0;
    for (int j = std::max(0, k - 1); j <= std::min(n - 1, k + 1); ++j)
      sum += raw[static_cast<std::size_t>(j)], ++count;
    smooth[static_cast<std::size_t>(k)] = sum / count;
  }
  int best = steps;
  for (int k = 0; k < n; ++k) {
    const double value = smooth[static_cast<std::size_t>(k)],
                 held = smooth[static_cast<std::size_t>(best)];
    if (value < held || (value == held && std::abs(k - steps) < std::abs(best - steps))) best = k;
  }
  SlideMinimum m{centre_m + (best - steps) * step_m,
                 smooth[static_cast<std::size_t>(steps)] - smooth[static_cast<std::size_t>(best)]};
  if (best > 0 && best < n - 1) {
    const double below = smooth[static_cast<std::size_t>(best - 1)],
                 at = smooth[static_cast<std::size_t>(best)],
                 above = smooth[static_cast<std::size_t>(best + 1)];
    const double curvature = below - 2.0 * at + above;
    if (curvature > 0.0) m.offset_m += 0.5 * step_m * (below - above) / curvature;
  }
  return m;
}

void PlaceAlongFreeDirections(const PointCloud& segment, const SceneAround& around,
                              const ScanContext& ctx, PosedObject& posed) {
  const ObjectModel& model = ctx.db.objects[posed.object];
  const ModelIndexes& indexes = ctx.cache.Model(posed.object);
  const NearestGrid& model_grid = indexes.nearest();
  const double voxel_m = ctx.db.parameters.voxel_m, radius_m = 0.5 * model.diameter_m;
  const PoseConstraints constraints = AnalysePoseConstraints(
      posed.fine.information, Eigen::Matrix<double, 6, 6>::Zero(), model.model.origin,
      std::max(posed.fine.inlier_plane_rmse, 1e-5), radius_m, ctx.options.free_direction_std_m);
  const IcpOptions last =
      FineIcpLastStage(model.diameter_m, ctx.db.parameters, ctx.options.threads);
  const double min_gain = std::max(10.0, 0.02 * static_cast<double>(segment.size()));
  for (const FreeDirection& free : constraints.free_O) {
    const bool slide = free.motion == FreeMotion::kTranslation;
    // The model moved by `offset_m` along the free direction (a turn's arc at the radius), in its
    // frame.
    auto motion_O = [&](double offset_m) -> Eigen::Isometry3d {
      if (slide) return Eigen::Isometry3d(Eigen::Translation3d(offset_m * free.axis_S));
      return Eigen::Translation3d(free.point_S) *
             Eigen::AngleAxisd(offset_m / radius_m, free.axis_S) *
             Eigen::Translation3d(-free.point_S);
    };
    const double reach_m = slide ? radius_m : 0.25 * std::numbers::pi * radius_m;
    const Eigen::Isometry3d T_O_S = posed.fine.T_target_source;
    auto slid = [&](double offset_m) { return motion_O(offset_m).inverse() * T_O_S; };
    auto cost = [&](double offset_m) {
      return Unexplained(segment, model, model_grid, around, slid(offset_m), ctx);
    };
    const int threads = ctx.options.threads;
    const SlideMinimum coarse = SmoothedMinimum(cost, 0.0, 2.0 * voxel_m, reach_m, threads);
    if (coarse.gain < min_gain) continue;
    const SlideMinimum m = SmoothedMinimum(cost, std::round(coarse.offset_m / voxel_m) * voxel_m,
                                           0.5 * voxel_m, 3.0 * voxel_m, threads);
    PosedObject moved = posed;
    moved.fine = AlignIcp(segment, indexes.target, slid(m.offset_m), last);
    Verify(segment, model, model_grid, around, moved.fine, ctx, moved.candidate);
    if (moved.candidate.verified) posed = std::move(moved);
  }
}

void TurnToBetterHalfTurn(const PointCloud& segment, const SceneAround& around,
                          const ScanContext& ctx, PosedObject& posed) {
  const std::vector<PosedObject> turned = HalfTurnedPoses(segment, posed, around, ctx);
  const PosedObject* best = &posed;
  for (const PosedObject& t : turned) {
    if (Better(t.candidate, best->candidate)) best = &t;
  }
  if (best == &posed) return;
  // On every point, as PoseOnSegment ends.
  const ObjectModel& model = ctx.db.objects[posed.object];
  const ModelIndexes& indexes = ctx.cache.Model(posed.object);
  PosedObject moved = *best;
  moved.fine = AlignIcp(segment, indexes.target, best->fine.T_target_source,
                        FineIcpLastStage(model.diameter_m, ctx.db.parameters, ctx.options.threads));
  Verify(segment, model, indexes.nearest(), around, moved.fine, ctx, moved.candidate);
  if (Better(moved.candidate, posed.candidate)) posed = std::move(moved);
}

// Other poses of a posed object the scan cannot tell from its own (RecognizedObject::
// equivalent_poses_S): its pose turned by each of DistinctHalfTurns (a nearly symmetric object,
// a valve's body, fits either way), refined by the fine ICP and verified like it; kept when
// verified, scoring within score_tie of it and more than 5 degrees or 2 voxels from it and from
// each other modulo the object's symmetries. T_S_O each.
std::vector<Eigen::Isometry3d> EquivalentPoses(const DescribedSegment& s, const PosedObject& posed,
                                               const SceneAround& around, const ScanContext& ctx) {
  const ObjectModel& model = ctx.db.objects[posed.object];
  const ObjectDatabaseParameters& p = ctx.db.parameters;
  std::vector<Eigen::Vector3d> points_O;
  for (std::size_t i = 0; i < model.model.size(); i += 4) points_O.push_back(model.model.Point(i));
  const double same_rad = 5.0 * std::numbers::pi / 180.0, same_m = 2.0 * p.voxel_m;
  std::vector<Eigen::Isometry3d> equivalent;
  for (const PosedObject& t : HalfTurnedPoses(s.cloud, posed, around, ctx)) {
    const RecognitionCandidate& c = t.candidate;
    if (!c.verified || c.score < posed.candidate.score - ctx.options.score_tie) continue;
    bool seen = false;
    for (const Eigen::Isometry3d& other : equivalent) {
      const SymmetricPoseError e =
          PoseErrorModuloSymmetry(c.T_S_O, other, points_O, model.symmetries);
      seen |= e.rotation_rad < same_rad && e.translation_m < same_m;
    }
    const SymmetricPoseError e =
        PoseErrorModuloSymmetry(c.T_S_O, posed.candidate.T_S_O, points_O, model.symmetries);
    seen |= e.rotation_rad < same_rad && e.translation_m < same_m;
    if (!seen) equivalent.push_back(c.T_S_O);
  }
  return equivalent;
}

}  // namespace uwscan::perception::recognition
