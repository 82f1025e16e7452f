#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "perception/cloud/point_cloud.hpp"
#include "perception/features/fpfh.hpp"
#include "perception/registration/registration_result.hpp"

namespace uwscan::perception {

struct CoarseAlignmentOptions {
  int k_nearest = 1;            // neighbours in descriptor space taken per source keypoint, >= 1
  bool mutual_filter = true;    // keep (s, t) only when s is also among t's k nearest
  int max_iterations = 100000;  // RANSAC hypotheses drawn, pre-rejected ones included, > 0
  // Stop once this probability of having drawn an all-inlier sample is reached, given the best
  // inlier ratio so far (checked every 512 hypotheses); in (0, 1], 1 = always max_iterations.
  double confidence = 0.999;
  // Pre-rejection (Buch et al. 2013): a sample survives only if each of its 3 edges has
  // shorter / longer >= this between source and target; in (0, 1).
  double edge_similarity = 0.9;
  double inlier_distance_m = 0.01;    // metres: |T s - t| below this makes a pair an inlier, > 0
  double min_inlier_fraction = 0.05;  // fitness needed for converged = true, in [0, 1]
  std::uint64_t seed = 0;             // RANSAC sample stream
  int threads = 0;                    // OpenMP threads, 0 = OpenMP's default, >= 0
  // The best hypotheses by inlier correspondences are verified on the clouds themselves: the
  // one that brings most source points within inlier_distance_m of a target point wins (as
  // PCL's prerejective scores). Repeated structure gives wrong hypotheses many consistent
  // correspondences; it rarely gives them more overlap. 0 = no verification; >= 0.
  int verified_hypotheses = 32;
  int verification_points = 1000;  // source points (evenly strided) the overlap is counted on, > 0

  // Throws uwscan::Error naming the field when a value is out of range.
  void Check() const;
};

// A pair of keypoints matched in descriptor space.
struct FeatureCorrespondence {
  std::size_t source_feature = 0;  // position in the source FpfhFeatures (not a cloud index)
  std::size_t target_feature = 0;  // position in the target FpfhFeatures
  float distance = 0.0f;           // Euclidean distance between the two descriptors
};

// For every source descriptor, its k nearest target descriptors (Euclidean, exact brute force,
// parallel over source descriptors; equal distances go to the lower index). With
// mutual_filter, a pair is kept only if the source descriptor is also among the k nearest
// source descriptors of the target one. Ordered by source feature, then by distance. The
// result is the same for any thread count. Throws uwscan::Error when k_nearest < 1, threads
// < 0, or a descriptor is not finite.
std::vector<FeatureCorrespondence> MatchFeatures(const FpfhFeatures& source,
                                                 const FpfhFeatures& target, int k_nearest,
                                                 bool mutual_filter, int threads = 0);

// Coarse rigid alignment of source onto target from keypoint descriptors: correspondences by
// MatchFeatures, then RANSAC over samples of 3 correspondences (Fischler & Bolles 1981) with
// the pre-rejection of Buch et al. 2013 (as PCL's SampleConsensusPrerejective): a sample whose
// edge lengths differ between source and target (options.edge_similarity) or that is collinear
// is dropped before it is solved (AlignSvd) and scored by its number of inlier correspondences
// (|T s - t| < options.inlier_distance_m). The best hypothesis (most inliers, then the lowest
// hypothesis index) is refitted on its inliers (AlignSvd), repeated while the inlier set changes
// without shrinking, at most 10 times. With options.verified_hypotheses > 0 the best of that
// many (by inliers, then index) is chosen by its overlap of the clouds instead.
//
// Determinism: hypothesis i draws its sample from a SplitMix64 stream keyed by (seed, i) and is
// evaluated independently; hypotheses run in blocks of 512 across threads and the adaptive stop
// (options.confidence) is tested between blocks, so any thread count gives the same result.
//
// Result: T_target_source; fitness = fraction of source keypoints with an inlier
// correspondence; inlier_rmse = RMS of |T s - t| over inlier correspondences (metres);
// iterations = hypotheses drawn; information = sum over inlier correspondences of J^T J with
// J = [-[p]x, I] (p = T s relative to target.origin; rotation about target.origin, then
// translation, target frame). converged = at least 3 inliers and fitness >=
// options.min_inlier_fraction. With fewer than 3 correspondences or no hypothesis surviving
// pre-rejection, converged = false with the identity; an unconvincing best hypothesis is
// returned with converged = false. Keypoint positions are taken relative to each cloud's origin
// in double, so origins 1e6 m apart are fine.
// Throws uwscan::Error on an empty or non-finite cloud, features whose indices and
// descriptors differ in number, an index out of range of its cloud, a non-finite descriptor,
// or invalid options.
RegistrationResult AlignCoarse(const PointCloud& source, const FpfhFeatures& source_features,
                               const PointCloud& target, const FpfhFeatures& target_features,
                               const CoarseAlignmentOptions& options = {});

}  // namespace uwscan::perception
