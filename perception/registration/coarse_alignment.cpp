#include "perception/registration/coarse_alignment.hpp"

#include <omp.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>
#include <string>
#include <utility>

#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/registration/svd_alignment.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::perception {
namespace {

constexpr int kDescriptorSize = FpfhDescriptor::RowsAtCompileTime;
constexpr int kBlockSize = 512;  // hypotheses between two tests of the adaptive stop
constexpr int kMaxRefits = 10;

int ThreadCount(int threads) { return threads > 0 ? threads : omp_get_max_threads(); }

// SplitMix64 (Steele, Lea & Flood 2014): a counter-based generator, so every hypothesis gets
// its own stream from (seed, index) alone.
std::uint64_t Mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

class SampleStream {
 public:
  SampleStream(std::uint64_t seed, std::uint64_t index)
      : state_(Mix64(seed + 0x9e3779b97f4a7c15ULL) ^ Mix64(index + 0x632be59bd9b4e019ULL)) {}

  std::uint64_t Next() {
    state_ += 0x9e3779b97f4a7c15ULL;
    return Mix64(state_);
  }
  // Uniform in [0, n), n > 0, without modulo bias.
  std::size_t Below(std::size_t n) {
    const std::uint64_t bound = static_cast<std::uint64_t>(n);
    const std::uint64_t limit = std::numeric_limits<std::uint64_t>::max() -
                                std::numeric_limits<std::uint64_t>::max() % bound;
    std::uint64_t x = Next();
    while (x >= limit) x = Next();
    return static_cast<std::size_t>(x % bound);
  }

 private:
  std::uint64_t state_;
};

void RequireValidFeatures(const FpfhFeatures& features, const PointCloud& cloud,
                          const std::string& what) {
  if (features.indices.size() != features.descriptors.size()) {
    throw Error("AlignCoarse: " + what + " has " + std::to_string(features.indices.size()) +
                " indices but " + std::to_string(features.descriptors.size()) + " descriptors");
  }
  for (std::size_t i = 0; i < features.indices.size(); ++i) {
    if (features.indices[i] >= cloud.size()) {
      throw Error("AlignCoarse: " + what + ".indices[" + std::to_string(i) +
                  "] = " + std::to_string(features.indices[i]) + " is out of range of a cloud of " +
                  std::to_string(cloud.size()) + " points");
    }
    if (!features.descriptors[i].allFinite()) {
      throw Error("AlignCoarse: " + what + ".descriptors[" + std::to_string(i) + "] is not finite");
    }
  }
}

void RequireFiniteDescriptors(const FpfhFeatures& features, const std::string& what) {
  for (std::size_t i = 0; i < features.descriptors.size(); ++i) {
    if (!features.descriptors[i].allFinite()) {
      throw Error("MatchFeatures: " + what + ".descriptors[" + std::to_string(i) +
                  "] is not finite");
    }
  }
}

// A candidate neighbour: squared descriptor distance and index, compared as a pair so that
// equal distances go to the lower index whatever order the candidates arrive in.
using Candidate = std::pair<float, std::size_t>;

// Inserts c into the sorted list [first, first + k) if it ranks among its k best.
void Insert(Candidate* first, std::size_t k, const Candidate& c) {
  if (!(c < first[k - 1])) return;
  std::size_t at = k - 1;
  while (at > 0 && c < first[at - 1]) {
    first[at] = first[at - 1];
    --at;
  }
  first[at] = c;
}

struct Neighbours {
  std::vector<std::vector<Candidate>> forward;   // per source: k nearest targets, nearest first
  std::vector<std::vector<Candidate>> backward;  // per target: k nearest sources (if asked)
};

// Exact k nearest neighbours in both directions from one pass over all (source, target)
// distances. The squared distances of one source to all targets are accumulated dimension by
// dimension over a structure-of-arrays copy of the targets (the inner loop runs over
// contiguous targets and vectorises; the summation order per pair is fixed). Rows run in
// parallel; each thread keeps its own k best sources per target, merged afterwards under the
// (distance, index) order, so the result does not depend on the thread count.
Neighbours NearestDescriptors(const std::vector<FpfhDescriptor>& source,
                              const std::vector<FpfhDescriptor>& target, int k, bool backward,
                              int threads) {
  const std::size_t n_source = source.size(), n_target = target.size();
  const std::size_t k_forward = std::min(static_cast<std::size_t>(k), n_target);
  const std::size_t k_backward = std::min(static_cast<std::size_t>(k), n_source);
  const Candidate none(std::numeric_limits<float>::infinity(),
                       std::numeric_limits<std::size_t>::max());
  std::vector<float> columns(static_cast<std::size_t>(kDescriptorSize) * n_target);
  for (std::size_t j = 0; j < n_target; ++j) {
    for (int d = 0; d < kDescriptorSize; ++d) columns[d * n_target + j] = target[j](d);
  }
  Neighbours result;
  result.forward.resize(n_source);
  const int thread_count = ThreadCount(threads);
  std::vector<std::vector<Candidate>> thread_backward(static_cast<std::size_t>(thread_count));
#pragma omp parallel num_threads(thread_count)
  {
    std::vector<float> squared(n_target);
    std::vector<Candidate> best(k_forward);
    std::vector<Candidate>& columns_best =
        thread_backward[static_cast<std::size_t>(omp_get_thread_num())];
    if (backward) columns_best.assign(n_target * k_backward, none);
#pragma omp for schedule(dynamic, 16)
    for (std::ptrdiff_t row = 0; row < static_cast<std::ptrdiff_t>(n_source); ++row) {
      const auto i = static_cast<std::size_t>(row);
      std::fill(squared.begin(), squared.end(), 0.0f);
      for (int d = 0; d < kDescriptorSize; ++d) {
        const float q = source[i](d);
        const float* column = columns.data() + d * n_target;
        for (std::size_t j = 0; j < n_target; ++j) {
          const float diff = column[j] - q;
          squared[j] += diff * diff;
        }
      }
      std::fill(best.begin(), best.end(), none);
      for (std::size_t j = 0; j < n_target; ++j) Insert(best.data(), k_forward, {squared[j], j});
      result.forward[i] = best;
      if (backward) {
        for (std::size_t j = 0; j < n_target; ++j) {
          Insert(columns_best.data() + j * k_backward, k_backward, {squared[j], i});
        }
      }
    }
  }
  if (backward) {
    result.backward.resize(n_target);
    std::vector<Candidate> merged(k_backward);
    for (std::size_t j = 0; j < n_target; ++j) {
      std::fill(merged.begin(), merged.end(), none);
      for (const std::vector<Candidate>& per_thread : thread_backward) {
        if (per_thread.empty()) continue;  // a thread OpenMP did not start
        for (std::size_t r = 0; r < k_backward; ++r) {
          Insert(merged.data(), k_backward, per_thread[j * k_backward + r]);
        }
      }
      result.backward[j] = merged;
    }
  }
  return result;
}

// Keypoint positions relative to their cloud's origin, in double.
std::vector<Eigen::Vector3d> KeypointPositions(const PointCloud& cloud,
                                               const FpfhFeatures& features) {
  std::vector<Eigen::Vector3d> positions;
  positions.reserve(features.indices.size());
  for (std::size_t index : features.indices) {
    positions.push_back(cloud.points[index].cast<double>());
  }
  return positions;
}

struct Pairs {
  std::vector<Eigen::Vector3d> source;  // relative to the source origin
  std::vector<Eigen::Vector3d> target;  // relative to the target origin
  std::vector<std::size_t> source_feature;
};

// Edge-length pre-rejection of Buch et al. 2013: every edge of the sample has about the same
// length in source and target.
bool EdgesSimilar(const Pairs& pairs, const std::array<std::size_t, 3>& sample, double similarity) {
  for (int e = 0; e < 3; ++e) {
    const std::size_t a = sample[e], b = sample[(e + 1) % 3];
    const double source_length = (pairs.source[a] - pairs.source[b]).norm();
    const double target_length = (pairs.target[a] - pairs.target[b]).norm();
    const double longer = std::max(source_length, target_length);
    if (!(longer > 0.0) || std::min(source_length, target_length) < similarity * longer) {
      return false;
    }
  }
  return true;
}

int CountInliers(const Pairs& pairs, const Eigen::Isometry3d& T, double threshold_sq) {
  const Eigen::Matrix3d R = T.linear();
  const Eigen::Vector3d t = T.translation();
  int count = 0;
  for (std::size_t i = 0; i < pairs.source.size(); ++i) {
    count += (R * pairs.source[i] + t - pairs.target[i]).squaredNorm() < threshold_sq ? 1 : 0;
  }
  return count;
}

std::vector<std::size_t> Inliers(const Pairs& pairs, const Eigen::Isometry3d& T,
                                 double threshold_sq) {
  std::vector<std::size_t> inliers;
  for (std::size_t i = 0; i < pairs.source.size(); ++i) {
    if ((T * pairs.source[i] - pairs.target[i]).squaredNorm() < threshold_sq) {
      inliers.push_back(i);
    }
  }
  return inliers;
}

struct Hypothesis {
  int inliers = -1;
  std::int64_t index = std::numeric_limits<std::int64_t>::max();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();

  bool BetterThan(const Hypothesis& other) const {
    return inliers > other.inliers || (inliers == other.inliers && index < other.index);
  }
};

// Hypotheses needed to draw an all-inlier sample of 3 with the given confidence.
double RequiredIterations(double inlier_ratio, double confidence) {
  if (confidence >= 1.0) return std::numeric_limits<double>::infinity();
  const double all_inliers = inlier_ratio * inlier_ratio * inlier_ratio;
  if (all_inliers >= 1.0) return 1.0;
  if (all_inliers <= 0.0) return std::numeric_limits<double>::infinity();
  return std::log(1.0 - confidence) / std::log1p(-all_inliers);
}

// Keeps the `capacity` best hypotheses (BetterThan order, a total order since indices are
// unique), so the kept set does not depend on the order hypotheses arrive in.
void KeepBest(std::vector<Hypothesis>* kept, const Hypothesis& candidate, std::size_t capacity) {
  if (kept->size() == capacity && !candidate.BetterThan(kept->back())) return;
  const auto at =
      std::upper_bound(kept->begin(), kept->end(), candidate,
                       [](const Hypothesis& a, const Hypothesis& b) { return a.BetterThan(b); });
  kept->insert(at, candidate);
  if (kept->size() > capacity) kept->pop_back();
}

// RANSAC; returns the `capacity` best hypotheses, best first.
std::vector<Hypothesis> Ransac(const Pairs& pairs, const CoarseAlignmentOptions& options,
                               std::size_t capacity, int* drawn) {
  const std::size_t n = pairs.source.size();
  const double threshold_sq = options.inlier_distance_m * options.inlier_distance_m;
  std::vector<Hypothesis> best;
  std::int64_t begin = 0;
  while (begin < options.max_iterations) {
    const std::int64_t end = std::min<std::int64_t>(begin + kBlockSize, options.max_iterations);
#pragma omp parallel num_threads(ThreadCount(options.threads))
    {
      std::vector<Hypothesis> thread_best;
#pragma omp for schedule(dynamic, 8) nowait
      for (std::int64_t it = begin; it < end; ++it) {
        SampleStream stream(options.seed, static_cast<std::uint64_t>(it));
        std::array<std::size_t, 3> sample{};
        sample[0] = stream.Below(n);
        do sample[1] = stream.Below(n);
        while (sample[1] == sample[0]);
        do sample[2] = stream.Below(n);
        while (sample[2] == sample[0] || sample[2] == sample[1]);
        if (!EdgesSimilar(pairs, sample, options.edge_similarity)) continue;
        const std::array<Eigen::Vector3d, 3> s = {pairs.source[sample[0]], pairs.source[sample[1]],
                                                  pairs.source[sample[2]]};
        const std::array<Eigen::Vector3d, 3> t = {pairs.target[sample[0]], pairs.target[sample[1]],
                                                  pairs.target[sample[2]]};
        const SvdAlignment fit = AlignSvd(s, t);
        if (fit.status != SvdAlignmentStatus::kSuccess) continue;
        Hypothesis candidate;
        candidate.inliers = CountInliers(pairs, fit.T_target_source, threshold_sq);
        candidate.index = it;
        candidate.T = fit.T_target_source;
        KeepBest(&thread_best, candidate, capacity);
      }
#pragma omp critical(uwscan_coarse_alignment_best)
      for (const Hypothesis& h : thread_best) KeepBest(&best, h, capacity);
    }
    begin = end;
    if (!best.empty() && best.front().inliers > 0 &&
        static_cast<double>(begin) >=
            RequiredIterations(static_cast<double>(best.front().inliers) / static_cast<double>(n),
                               options.confidence)) {
      break;
    }
  }
  *drawn = static_cast<int>(begin);
  return best;
}

// Source points (relative to the source origin, evenly strided) within `distance` of a target
// point once moved by T_rel (which maps source-relative to target-relative coordinates).
int Overlap(const std::vector<Eigen::Vector3d>& source_points, const KnnIndex& target_index,
            const Eigen::Isometry3d& T_rel, double distance) {
  std::vector<std::uint32_t> index;
  std::vector<float> squared;
  const float limit = static_cast<float>(distance * distance);
  int count = 0;
  for (const Eigen::Vector3d& p : source_points) {
    target_index.Query((T_rel * p).cast<float>(), 1, index, squared);
    count += !squared.empty() && squared.front() < limit ? 1 : 0;
  }
  return count;
}

// Of the candidates (best by inliers first), the one with the most overlap; ties keep the
// better-by-inliers one. Evaluated in parallel, chosen in a fixed order: thread-count free.
Hypothesis MostOverlapping(const std::vector<Hypothesis>& candidates, const PointCloud& source,
                           const PointCloud& target, const CoarseAlignmentOptions& options) {
  const std::size_t stride = std::max<std::size_t>(
      1, source.size() / static_cast<std::size_t>(options.verification_points));
  std::vector<Eigen::Vector3d> points;
  for (std::size_t i = 0; i < source.size(); i += stride)
    points.push_back(source.points[i].cast<double>());
  const KnnIndex target_index(target.points);
  std::vector<int> overlap(candidates.size(), 0);
#pragma omp parallel for num_threads(ThreadCount(options.threads)) schedule(dynamic, 1)
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    overlap[c] = Overlap(points, target_index, candidates[c].T, options.inlier_distance_m);
  }
  std::size_t chosen = 0;
  for (std::size_t c = 1; c < candidates.size(); ++c) {
    if (overlap[c] > overlap[chosen]) chosen = c;
  }
  return candidates[chosen];
}

}  // namespace

void CoarseAlignmentOptions::Check() const {
  const OptionChecks check("CoarseAlignmentOptions");
  check.AtLeast("k_nearest", k_nearest, 1);
  check.GreaterThan("max_iterations", max_iterations, 0);
  check.InRange("confidence", confidence, 0.0, 1.0, Interval::kOpenLow);
  check.InRange("edge_similarity", edge_similarity, 0.0, 1.0, Interval::kOpen);
  check.Positive("inlier_distance_m", inlier_distance_m, "m");
  check.InRange("min_inlier_fraction", min_inlier_fraction, 0.0, 1.0);
  check.AtLeast("threads", threads, 0, "(0 = OpenMP's default)");
  check.AtLeast("verified_hypotheses", verified_hypotheses, 0);
  check.GreaterThan("verification_points", verification_points, 0);
}

std::vector<FeatureCorrespondence> MatchFeatures(const FpfhFeatures& source,
                                                 const FpfhFeatures& target, int k_nearest,
                                                 bool mutual_filter, int threads) {
  if (k_nearest < 1) throw Error("MatchFeatures: k_nearest must be >= 1");
  if (threads < 0) throw Error("MatchFeatures: threads must be >= 0");
  RequireFiniteDescriptors(source, "source");
  RequireFiniteDescriptors(target, "target");
  std::vector<FeatureCorrespondence> matches;
  if (source.descriptors.empty() || target.descriptors.empty()) return matches;
  const Neighbours neighbours =
      NearestDescriptors(source.descriptors, target.descriptors, k_nearest, mutual_filter, threads);
  for (std::size_t i = 0; i < neighbours.forward.size(); ++i) {
    for (const auto& [squared, j] : neighbours.forward[i]) {
      if (mutual_filter) {
        const std::vector<Candidate>& back = neighbours.backward[j];
        const bool mutual = std::any_of(back.begin(), back.end(),
                                        [i](const Candidate& c) { return c.second == i; });
        if (!mutual) continue;
      }
      matches.push_back({i, j, std::sqrt(squared)});
    }
  }
  return matches;
}

RegistrationResult AlignCoarse(const PointCloud& source, const FpfhFeatures& source_features,
                               const PointCloud& target, const FpfhFeatures& target_features,
                               const CoarseAlignmentOptions& options) {
  options.Check();
  RequireValidCloud(source, "AlignCoarse: source");
  RequireValidCloud(target, "AlignCoarse: target");
  RequireValidFeatures(source_features, source, "source_features");
  RequireValidFeatures(target_features, target, "target_features");

  const std::vector<FeatureCorrespondence> matches = MatchFeatures(
      source_features, target_features, options.k_nearest, options.mutual_filter, options.threads);
  const std::vector<Eigen::Vector3d> source_keypoints = KeypointPositions(source, source_features);
  const std::vector<Eigen::Vector3d> target_keypoints = KeypointPositions(target, target_features);
  Pairs pairs;
  for (const FeatureCorrespondence& match : matches) {
    pairs.source.push_back(source_keypoints[match.source_feature]);
    pairs.target.push_back(target_keypoints[match.target_feature]);
    pairs.source_feature.push_back(match.source_feature);
  }

  RegistrationResult result;
  if (pairs.source.size() < 3) return result;
  int drawn = 0;
  const std::vector<Hypothesis> candidates = Ransac(
      pairs, options, static_cast<std::size_t>(std::max(1, options.verified_hypotheses)), &drawn);
  result.iterations = drawn;
  if (candidates.empty()) return result;
  const Hypothesis best = options.verified_hypotheses > 0
                              ? MostOverlapping(candidates, source, target, options)
                              : candidates.front();

  // Refit on the inliers while that gains inliers. T_rel maps source-relative coordinates to
  // target-relative ones.
  const double threshold_sq = options.inlier_distance_m * options.inlier_distance_m;
  Eigen::Isometry3d T_rel = best.T;
  std::vector<std::size_t> inliers = Inliers(pairs, T_rel, threshold_sq);
  for (int refit = 0; refit < kMaxRefits && inliers.size() >= 3; ++refit) {
    std::vector<Eigen::Vector3d> s, t;
    for (std::size_t i : inliers) {
      s.push_back(pairs.source[i]);
      t.push_back(pairs.target[i]);
    }
    const SvdAlignment fit = AlignSvd(s, t);
    if (fit.status != SvdAlignmentStatus::kSuccess) break;
    std::vector<std::size_t> refit_inliers = Inliers(pairs, fit.T_target_source, threshold_sq);
    if (refit_inliers.size() < inliers.size()) break;
    const bool unchanged = refit_inliers == inliers;
    T_rel = fit.T_target_source;
    inliers = std::move(refit_inliers);
    if (unchanged) break;
  }

  std::vector<char> source_has_inlier(source_features.indices.size(), 0);
  double squared_sum = 0.0;
  for (std::size_t i : inliers) {
    const Eigen::Vector3d p = T_rel * pairs.source[i];
    squared_sum += (p - pairs.target[i]).squaredNorm();
    source_has_inlier[pairs.source_feature[i]] = 1;
    Eigen::Matrix<double, 3, 6> J;
    J << Eigen::Matrix3d::Zero(), Eigen::Matrix3d::Identity();
    J(0, 1) = p.z();  // -[p]x
    J(0, 2) = -p.y();
    J(1, 0) = -p.z();
    J(1, 2) = p.x();
    J(2, 0) = p.y();
    J(2, 1) = -p.x();
    result.information += J.transpose() * J;
  }
  const auto keypoints_with_inlier =
      static_cast<double>(std::count(source_has_inlier.begin(), source_has_inlier.end(), char{1}));
  result.fitness = keypoints_with_inlier / static_cast<double>(source_features.indices.size());
  result.inlier_rmse =
      inliers.empty() ? 0.0 : std::sqrt(squared_sum / static_cast<double>(inliers.size()));
  result.T_target_source =
      Eigen::Translation3d(target.origin) * T_rel * Eigen::Translation3d(-source.origin);
  result.converged = inliers.size() >= 3 && result.fitness >= options.min_inlier_fraction;
  return result;
}

}  // namespace uwscan::perception
