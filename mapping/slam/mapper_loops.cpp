// Mapper's loop closures: candidates, their registration and the gates a loop must pass.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "mapping/slam/mapper_impl.hpp"
#include "mapping/slam/overlap_gate.hpp"
#include "perception/registration/icp.hpp"
#include "scanner/common/symmetrized.hpp"

namespace uwscan::mapping {
namespace {

using mapper_steps::AppendMoved;
using mapper_steps::Clock;
using mapper_steps::Since;

// Covariance of the position of `to` seen from `from`'s frame, from the [w, v] covariance of
// T_from_to: the rotation moves it by w x t.
Eigen::Matrix3d PositionCovariance(const Matrix6d& covariance, const Eigen::Vector3d& t) {
  Eigen::Matrix<double, 3, 6> J;
  Eigen::Matrix3d minus_skew;
  minus_skew << 0.0, t.z(), -t.y(), -t.z(), 0.0, t.x(), t.y(), -t.x(), 0.0;
  J << minus_skew, Eigen::Matrix3d::Identity();
  return J * covariance * J.transpose();
}

// The covariance of a motion predicted to `covariance` and measured with `information`.
Matrix6d Fused(const Matrix6d& covariance, const Matrix6d& information) {
  return Symmetrized(Matrix6d((covariance.inverse() + information).inverse()));
}

double LargestStd(const Eigen::Matrix3d& covariance) {
  return std::sqrt(
      std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvalues()(2)));
}

// How far the prediction of k's origin may be off: its largest position std.
double PredictionStd(const Matrix6d& covariance, const Eigen::Isometry3d& T_j_k) {
  return LargestStd(PositionCovariance(covariance, T_j_k.translation()));
}

}  // namespace

// Loop closures for submap k: the earlier submaps whose overlap with it is plausible, nearest
// first, each registered from the predicted pose and judged (JudgeLoop); an accepted one becomes
// an edge between the two scans.
void Mapper::Impl::TryLoopClosures(int k) {
  if (options.max_loop_candidates == 0 || k % options.loop_every_submaps != 0) return;
  // Over a bare seabed no loop can pin the directions the gate asks for, however long ICP slides
  // about (bench/slam/RESULTS.md: two fifths of the loops' ICP time). A registration weighs only
  // the pairs it makes, so it can pin one direction more than the submap's whole surface does.
  if (submaps[static_cast<size_t>(k)].surface_directions < options.loop_min_directions - 1) {
    ++stats.loops_not_tried_plain;
    return;
  }
  const Clock::time_point start = Clock::now();
  PlaceCentres(centres.held(), k - options.loop_min_index_gap);
  for (const LoopCandidate& c : LoopCandidates(k)) {
    const perception::RegistrationResult r =
        Register(submaps[static_cast<size_t>(k)], LoopTarget(c.j, k), c.predicted.T_j_k,
                 c.predicted.covariance, LoopIcpDistances(c.predicted));
    const LoopClosure loop = JudgeLoop(r, c, k);
    if (loop.accepted) {
      graph.AddEdge({.from = ScanNode(c.j),
                     .to = ScanNode(k),
                     .T_from_to = r.T_target_source,
                     .information = loop.information,
                     .robust = true});
      shortcuts.push_back(
          {.a = c.j, .b = k, .covariance = Fused(c.predicted.covariance, loop.information)});
    }
    loops.push_back(loop);
  }
  stats.stage_seconds.loop_s += Since(start);
}

std::vector<Mapper::Impl::LoopCandidate> Mapper::Impl::LoopCandidates(int k) const {
  const Submap& current = submaps[static_cast<size_t>(k)];
  const Eigen::Vector3d centre_k = ScanPose(k) * current.centroid_V;  // in the world
  // The cheap first cut, far beyond any gate here: centres within 2 m of overlapping, from the
  // grid's cells around k (every submap it holds is loop_min_index_gap or more behind k).
  // The grid is asked a millimetre further, so that rounding cannot leave out a centre on the
  // edge.
  constexpr double kFirstCutSlackM = 2.0;
  const double reach_m =
      kFirstCutSlackM + 0.001 + options.loop_overlap_ratio * (largest_radius_m + current.radius_m);
  std::vector<std::pair<int, double>> near;  // submap, distance, in ascending submap order
  for (const int j : centres.Near(centre_k, reach_m)) {
    const Submap& old = submaps[static_cast<size_t>(j)];
    const double distance = (ScanPose(j) * old.centroid_V - centre_k).norm();
    const double overlap = options.loop_overlap_ratio * (old.radius_m + current.radius_m);
    if (distance - overlap <= kFirstCutSlackM) near.emplace_back(j, distance);
  }
  // Candidates are tried nearest first (of equally near ones, the older): the gate is asked of
  // the near submaps in that order until enough pass. Late in a long dive hundreds of earlier
  // submaps lie near a revisit, and the nearest usually passes.
  std::stable_sort(near.begin(), near.end(),
                   [](const auto& a, const auto& b) { return a.second < b.second; });
  ChainBack back_from_k(*this, k);
  std::vector<LoopCandidate> candidates;
  for (const auto& [j, distance] : near) {
    if (candidates.size() >= static_cast<size_t>(options.max_loop_candidates)) break;
    const Submap& old = submaps[static_cast<size_t>(j)];
    const double overlap = options.loop_overlap_ratio * (old.radius_m + current.radius_m);
    // In j's frame: how far k's centre is predicted from j's, and how uncertain that is.
    const LoopPrediction predicted = Predict(j, k, &back_from_k);
    const Eigen::Vector3d centre_k_in_j = predicted.T_j_k * current.centroid_V;
    const Eigen::Vector3d gap_m = centre_k_in_j - old.centroid_V;
    const Eigen::Matrix3d centre_covariance =
        PositionCovariance(predicted.covariance, centre_k_in_j);
    if (!(MahalanobisGapToOverlap(gap_m, overlap, centre_covariance) <= options.gate_sigmas)) {
      continue;
    }
    candidates.push_back({j, distance, predicted});
  }
  return candidates;
}

void Mapper::Impl::PlaceCentres(int from, int to) {
  for (int j = from; j <= to; ++j) {
    const Submap& s = submaps[static_cast<size_t>(j)];
    centres.Place(j, ScanPose(j) * s.centroid_V);
    largest_radius_m = std::max(largest_radius_m, s.radius_m);
  }
}

const Matrix6d& Mapper::Impl::ChainBack::To(int j) {
  for (int i = k_ - static_cast<int>(chain_.size()); i >= j; --i) {
    const Matrix6d ad = Adjoint(mapper_.ScanPose(i).inverse() * mapper_.ScanPose(i + 1));
    chain_.push_back(mapper_.increment_covariance[static_cast<size_t>(i) + 1] +
                     ad * chain_.back() * ad.transpose());
  }
  return chain_[static_cast<size_t>(k_ - j)];
}

// Late in a dive the chain between a revisit and the submap it revisits is a thousand steps
// long, its position std near a metre: it would let a registration 10 cm off pass as consistent
// (bench/slam/RESULTS.md, "False loops on long dives"). The loops accepted since know the two
// places' relation far better; one of them, with the few steps from its ends to j and k, is the
// prediction's path. Where j lies between the loop's ends, the steps from its earlier end to j
// count in both factors, where their errors cancel: the sum overstates the covariance, the safe
// side for a gate.
Mapper::Impl::LoopPrediction Mapper::Impl::Predict(int j, int k, ChainBack* back_from_k) const {
  const LoopShortcut* best = nullptr;
  int fewest_steps = k - j;
  for (auto s = shortcuts.rbegin(); s != shortcuts.rend() && k - s->b < fewest_steps; ++s) {
    const int steps = (k - s->b) + std::abs(j - s->a);
    if (steps < fewest_steps) {
      best = &*s;
      fewest_steps = steps;
    }
  }
  const Eigen::Isometry3d T_j_k = ScanPose(j).inverse() * ScanPose(k);
  if (best == nullptr) return {T_j_k, back_from_k->To(j)};
  // T_j_k = T_j_a T_a_b T_b_k, each factor's covariance moved into j's frame.
  const Eigen::Isometry3d T_j_a = ScanPose(j).inverse() * ScanPose(best->a);
  const Matrix6d ad_j_a = Adjoint(T_j_a);
  const Matrix6d ad_j_b = Adjoint(ScanPose(j).inverse() * ScanPose(best->b));
  const Matrix6d j_to_a =
      best->a >= j ? ChainBack(*this, best->a).To(j)
                   : Matrix6d(ad_j_a * ChainBack(*this, j).To(best->a) * ad_j_a.transpose());
  return {T_j_k, Symmetrized(j_to_a + ad_j_a * best->covariance * ad_j_a.transpose() +
                             ad_j_b * back_from_k->To(best->b) * ad_j_b.transpose())};
}

perception::PointCloud Mapper::Impl::LoopTarget(int j, int k) const {
  perception::PointCloud target;
  for (int i = std::max(0, j - 1); i <= std::min(j + 1, k - options.loop_min_index_gap); ++i) {
    AppendMoved(store.Get(i)->cloud, ScanPose(j).inverse() * ScanPose(i), &target);
  }
  return target;
}

std::vector<double> Mapper::Impl::LoopIcpDistances(const LoopPrediction& predicted) const {
  // The first stage reaches as far as the prediction may be off: three times the largest
  // position std of the scan's origin (the gate asked the narrower question, whether the two
  // centres can meet at all).
  std::vector<double> distances = options.loop_icp_distances_m;
  const double reach = options.gate_sigmas * PredictionStd(predicted.covariance, predicted.T_j_k);
  if (reach > distances.front()) distances.insert(distances.begin(), reach);
  return distances;
}

LoopClosure Mapper::Impl::JudgeLoop(const perception::RegistrationResult& r, const LoopCandidate& c,
                                    int k) const {
  LoopClosure loop;
  loop.from = c.j;
  loop.to = k;
  loop.fitness = r.fitness;
  loop.T_from_to = r.T_target_source;
  KeptDirections kept;
  loop.information = RegistrationInformation(r, submaps[static_cast<size_t>(c.j)],
                                             submaps[static_cast<size_t>(k)], &kept);
  loop.constrained_directions = kept.count;
  loop.prediction_std_m = PredictionStd(c.predicted.covariance, c.predicted.T_j_k);
  // Where the registration puts k against where the graph does.
  const Vector6d miss = PoseError(r.T_target_source, c.predicted.T_j_k);
  loop.reason = LoopRejection(r, kept, loop.information, c.predicted.covariance, miss, &loop.chi2);
  loop.accepted = loop.reason.empty();
  loop.correction_chi2 = miss.dot(loop.information * miss);
  return loop;
}

// Along a pipe or over a flat seabed a loop pins only some directions: those are kept (the
// others, as for consecutive submaps, are left to the navigation), and the registration must be
// certain and consistent with the prediction in them. "" when it is.
std::string Mapper::Impl::LoopRejection(const perception::RegistrationResult& r,
                                        const KeptDirections& kept, const Matrix6d& information,
                                        const Matrix6d& prediction_covariance, const Vector6d& miss,
                                        double* chi2) const {
  const int constrained = kept.count;
  const double sigma_m = LargestStd(kept.covariance.bottomRightCorner<3, 3>());
  const double sigma_rad = LargestStd(kept.covariance.topLeftCorner<3, 3>());
  if (r.fitness < options.loop_min_fitness) {
    return "fitness " + std::to_string(r.fitness) + " below " +
           std::to_string(options.loop_min_fitness);
  }
  if (constrained < options.loop_min_directions) {
    return "degenerate: the scans pin " + std::to_string(constrained) + " directions, fewer than " +
           std::to_string(options.loop_min_directions);
  }
  if (sigma_m > options.loop_max_sigma_m || sigma_rad > options.loop_max_sigma_rad) {
    return "uncertain: registration std " + std::to_string(sigma_m) + " m, " +
           std::to_string(sigma_rad) + " rad";
  }
  *chi2 = miss.dot(InformationOfSum(information, prediction_covariance) * miss);
  if (!(*chi2 <= Chi2Quantile999(constrained))) {
    return std::string(kInconsistentLoop) + ": chi2 " + std::to_string(*chi2) + " in " +
           std::to_string(constrained) + " directions";
  }
  return "";
}

}  // namespace uwscan::mapping
