#include "perception/recognition/accepted_object.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "perception/recognition/free_directions.hpp"
#include "perception/recognition/object_database_builder.hpp"
#include "perception/recognition/object_symmetry.hpp"
#include "perception/recognition/residual_patches.hpp"
#include "perception/recognition/restart_spread.hpp"

namespace uwscan::perception::recognition {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

// Whether two rotation axes are the same line: the same direction (within a degree) through the
// same points (within 2 mm), both given in one frame.
bool SameAxis(const Eigen::Vector3d& axis_a, const Eigen::Vector3d& point_a,
              const Eigen::Vector3d& axis_b, const Eigen::Vector3d& point_b) {
  if (std::abs(axis_a.dot(axis_b)) < std::cos(kDegree)) return false;
  const Eigen::Vector3d d = point_a - point_b;
  return (d - d.dot(axis_b) * axis_b).norm() < 0.002;
}

// Whether a free rotation found in the data is one of the object's continuous symmetries, which
// are reported as such.
bool IsContinuousSymmetry(const FreeDirection& rotation_O, const ObjectModel& model) {
  return std::any_of(model.symmetries.begin(), model.symmetries.end(), [&](const SymmetryAxis& s) {
    return s.order == 0 && SameAxis(rotation_O.axis_S, rotation_O.point_S, s.axis_O, s.point_O);
  });
}

// Whether `rotation_O` turns about the same axis as a rotation among `free_O`.
bool AlreadyFree(const FreeDirection& rotation_O, const std::vector<FreeDirection>& free_O) {
  return std::any_of(free_O.begin(), free_O.end(), [&](const FreeDirection& f) {
    return f.motion == FreeMotion::kRotation &&
           SameAxis(rotation_O.axis_S, rotation_O.point_S, f.axis_S, f.point_S);
  });
}

// The turn about each N-fold symmetry axis (N >= 3) whose phase the data does not pin
// (SymmetryPhasePinned), added to `c` as a free rotation (in the object frame), and the
// covariance left without it: projected onto the twists orthogonal to the turn's.
void AddUnpinnedPhases(const PosedObject& posed, const PointCloud& fitted, const ObjectModel& model,
                       const ScanContext& ctx, PoseConstraints& c) {
  for (const SymmetryAxis& axis : model.symmetries) {
    if (SymmetryPhasePinned(fitted, model, ctx.cache.Model(posed.object).nearest(), axis,
                            posed.fine.T_target_source, ctx.db.parameters.voxel_m,
                            ctx.options.min_phase_points)) {
      continue;
    }
    FreeDirection turn;
    turn.kind = FreeKind::kUnconstrained;
    turn.motion = FreeMotion::kRotation;
    turn.axis_S = axis.axis_O.normalized();
    turn.point_S = axis.point_O;
    if (AlreadyFree(turn, c.free_O)) continue;
    c.free_O.push_back(turn);
    // The twist [w, v] of that turn about the covariance's centre (x -> x + w x (x - c) + v).
    Eigen::Matrix<double, 6, 1> twist;
    twist << turn.axis_S, turn.axis_S.cross(model.model.origin - turn.point_S);
    const Eigen::Matrix<double, 6, 6> project =
        Eigen::Matrix<double, 6, 6>::Identity() - twist * twist.transpose() / twist.squaredNorm();
    c.covariance = project * c.covariance * project.transpose();
  }
}

// The directions the fine ICP on `fitted` leaves free (those the object's continuous symmetries
// already name left out), and the phases the data leaves free about its N-fold axes, in the scan
// frame, and the covariance over the others.
void AddPoseConstraints(const PosedObject& posed, const PointCloud& fitted,
                        const ObjectModel& model, const ScanContext& ctx, RecognizedObject& out) {
  const double radius_m = 0.5 * model.diameter_m;
  const double pair_distance_m =
      FineIcp(model.diameter_m, ctx.db.parameters, 1).max_correspondence_distance_m.back();
  const Eigen::Matrix<double, 6, 6> spread = ResidualPatchSpread(
      fitted, posed.fine.T_target_source, model.model, ctx.cache.Model(posed.object).nearest(),
      pair_distance_m, model.model.origin, ctx.options.residual_patch_m);
  const Eigen::Matrix<double, 6, 6>& information = posed.fine.information;
  const double sigma_m = std::max(posed.fine.inlier_plane_rmse, 1e-5);
  PoseConstraints c =
      AnalysePoseConstraints(information, spread, model.model.origin, sigma_m, radius_m,
                             ctx.options.free_direction_std_m, ctx.options.pose_floor_std_m);
  if (ctx.options.pose_restart_voxels > 0.0) {
    // Where the fit comes to rest decides what it pins, as its information does.
    const Eigen::Matrix<double, 6, 6> rest = RestartSpread(
        fitted, ctx.cache.Model(posed.object).target, posed.fine.T_target_source,
        FineIcpLastStage(model.diameter_m, ctx.db.parameters, 1), c.covariance, model.model.origin,
        radius_m, ctx.options.pose_restart_voxels * ctx.db.parameters.voxel_m, ctx.options.threads);
    c = AnalysePoseConstraints(information, spread, model.model.origin, sigma_m, radius_m,
                               ctx.options.free_direction_std_m, ctx.options.pose_floor_std_m,
                               rest);
  }
  AddUnpinnedPhases(posed, fitted, model, ctx, c);
  const Eigen::Isometry3d& T_S_O = posed.candidate.T_S_O;
  for (FreeDirection f : c.free_O) {
    if (f.motion == FreeMotion::kRotation && IsContinuousSymmetry(f, model)) continue;
    f.axis_S = T_S_O.linear() * f.axis_S;
    f.point_S = T_S_O * f.point_S;
    out.free_directions.push_back(f);
  }
  out.covariance = c.covariance;
}

}  // namespace

// Verified candidates whose scores are within `tie` of the best one's are told apart by whether
// they rest on a support plane within `resting_m`, then by their views' chi-square: the scores
// cannot, an object floating over the seabed needs a support the scan does not show, and the ESF
// says which the segment looks more like (a pipe or a tee whose branch the sweep did not reach).
void BreakTie(double tie, double resting_m, std::vector<PosedObject>& ranked) {
  if (ranked.empty() || !ranked.front().candidate.verified) return;
  auto key = [&](const RecognitionCandidate& c) {
    return std::make_pair(c.clearance_m > resting_m, c.chi_square);
  };
  std::size_t pick = 0;
  for (std::size_t k = 1; k < ranked.size(); ++k) {
    const RecognitionCandidate& c = ranked[k].candidate;
    if (c.verified && c.score >= ranked.front().candidate.score - tie &&
        key(c) < key(ranked[pick].candidate)) {
      pick = k;
    }
  }
  std::rotate(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(pick),
              ranked.begin() + static_cast<std::ptrdiff_t>(pick) + 1);
}

// The verified candidates of `posed` that could still rank first placed along the directions their
// fits leave free (PlaceAlongFreeDirections), before they are ranked: a pipe seen with one end
// and left by its fit with the other end in view misses surface the scan saw through, and a wrong
// object that fits the same stretch would win. A candidate can rank first when it would score
// within score_tie of the best with nothing missing: placing it changes that share, not the
// others much. One that misses surface is first tried turned by its model's half turns
// (TurnToBetterHalfTurn): a flange posed end for end misses its rim where the scan shows its neck.
void PlaceContendersAlongFreeDirections(const PointCloud& segment, const SceneAround& around,
                                        const ScanContext& ctx, std::vector<PosedObject>& posed) {
  double best = 0.0;
  for (const PosedObject& q : posed)
    best = std::max(best, q.candidate.verified ? q.candidate.score : 0.0);
  for (PosedObject& q : posed) {
    const RecognitionCandidate& c = q.candidate;
    if (c.verified && c.close * (1.0 - c.buried) >= best - ctx.options.score_tie) {
      // Missing surface it should have shown: perhaps posed a half turn off.
      if (c.missing > ctx.options.score_tie) {
        TurnToBetterHalfTurn(segment, around, ctx, q);
      }
      PlaceAlongFreeDirections(segment, around, ctx, q);
    }
  }
}

// The other verified objects BreakTie chose among: scoring within `tie` of the best score.
std::vector<std::pair<std::string, Eigen::Isometry3d>> EquivalentObjects(
    const std::vector<PosedObject>& ranked, double tie) {
  double top = -std::numeric_limits<double>::infinity();
  for (const PosedObject& p : ranked) {
    if (p.candidate.verified) top = std::max(top, p.candidate.score);
  }
  std::vector<std::pair<std::string, Eigen::Isometry3d>> equivalent;
  for (std::size_t k = 1; k < ranked.size(); ++k) {
    const RecognitionCandidate& c = ranked[k].candidate;
    if (c.verified && c.score >= top - tie) equivalent.emplace_back(c.object_id, c.T_S_O);
  }
  return equivalent;
}

// The recognised object's identity, pose, free directions, covariance and grasps.
void Accept(const PosedObject& posed, const PointCloud& fitted, const ObjectModel& model,
            double other_chi_square, const ScanContext& ctx, RecognizedObject& object) {
  const RecognitionCandidate& best = posed.candidate;
  object.object_id = best.object_id;
  object.score = best.score;
  object.chi_square = best.chi_square;
  object.T_S_O = best.T_S_O;
  object.margin = std::isfinite(other_chi_square) && std::isfinite(best.chi_square)
                      ? other_chi_square - best.chi_square
                      : 0.0;
  for (const SymmetryAxis& s : model.symmetries) {
    FreeDirection f;
    f.kind = FreeKind::kSymmetry;
    f.motion = FreeMotion::kRotation;
    f.axis_S = best.T_S_O.linear() * s.axis_O;
    f.point_S = best.T_S_O * s.point_O;
    f.order = s.order;
    object.free_directions.push_back(f);
  }
  AddPoseConstraints(posed, fitted, model, ctx, object);
  for (const GraspFrame& g : model.grasps)
    object.grasps_S.emplace_back(g.name, best.T_S_O * g.T_O_G);
}

}  // namespace uwscan::perception::recognition
