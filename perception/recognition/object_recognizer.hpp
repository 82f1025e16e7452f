#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "perception/cloud/point_cloud.hpp"
#include "perception/recognition/free_directions.hpp"
#include "perception/recognition/object_database.hpp"

namespace uwscan::perception {

struct RecognitionOptions {
  double plane_distance_m = 0.01;  // seabed / wall inliers, metres
  // A plane is removed while it holds this share of the scan: the dominant one (the seabed),
  // then up to two more wider both ways than any object of the database (walls), never an
  // object's own flat face.
  double plane_min_fraction = 0.15;
  double cluster_tolerance_m = 0.025;  // points closer than this belong to one segment, metres
  int min_segment_points = 150;        // voxelised points; smaller segments are ignored...
  double attach_distance_m = 0.075;    // ...or join the nearest segment within this, metres
  int max_candidates = 3;              // objects among them whose pose is estimated
  // ...those whose nearest view is within this multiple of the best object's chi-square (in a
  // 100-scan bench the right object was at most 2.9x the best; a fifth of the candidates were
  // farther), >= 1.
  double max_chi_square_ratio = 4.0;
  // Pose starts per candidate: FPFH + RANSAC onto its nearest view, and for each of its
  // `pose_views` nearest views `pose_rolls` rolls about the line of sight (ViewPoseHypotheses).
  // Each start gets a short ICP on at most `sift_points` segment points; the `refined_starts`
  // best distinct ones by fit get the full ICP and the verification, and the best score wins
  // (poses the segment alone cannot tell apart, such as a valve body turned half a turn about
  // its stem, differ in the surface they leave unseen, e.g. where the handle is). On the
  // recognition bench's 100 scans 2 views posed 80.6 % of the objects within 5 mm and 2 degrees,
  // 3 80.8 %, 4 82.4 % (a lever valve no start had fitted, a flange 12 -> 1 degrees, a lever
  // 50 -> 0.3 degrees), 6 the same as 4 in more time. Refining 5 starts instead of 3 (the sift
  // ranks by fit alone, and a partial view fits several poses as well: an elbow's leg, a valve's
  // body) posed 86.7 % instead of 85.2 % of the objects within 5 mm and 2 degrees (seed 1) and
  // 80.2 % instead of 78.5 % (seed 2), and recognised an elbow and a pipe more on seed 2, for
  // about 0.02 s per scan; 4 did worse on seed 2 (a pipe answered as a flange), 6 no better.
  int pose_views = 4;
  int pose_rolls = 12;
  int sift_points = 200;
  int refined_starts = 5;
  int refine_points = 1000;  // segment points the fine ICP of each refined start uses
  // "unknown" when the nearest view is farther than this (chi-square, histograms summing to 1)
  double max_chi_square = 0.9;
  // Verification: at least this share of the segment within 1.5 voxels of the posed model...
  double min_fitness = 0.85;
  // ...at least this share within close_distance_m of the model's surface (point to plane:
  // the wrong object, or the right one in a wrong pose, lies near but not on it; a segment that
  // also holds a second object touching this one is left to be split)... At 0.6, 8 of the 9
  // answers under 0.85 in the bench's 100 scans were wrong (foreign meshes taken for a tee).
  double min_close = 0.85;
  double close_distance_m = 0.002;
  // ...and at most this share of the model surface the sensor should have seen where it saw
  // through it instead (MissingShare; only surface a line of sight came near counts). Set for the
  // former measure, which counted all unseen surface; on the bench's 100 scans with the present
  // one, 0.3 gave 123 recognised (124 at 0.45) and 0.2 the same answers as 0.45.
  double max_missing = 0.45;
  // A posed model's points deeper than this beyond a support plane removed from the scan (the
  // seabed) count as buried, and its score is scaled by the share of its points not buried
  // (SupportContact): objects rest on the seabed, they are not sunk into it.
  double buried_depth_m = 0.01;
  // Verified candidates scoring within this of the best are ranked by chi-square instead, those
  // resting on a support plane (their clearance within buried_depth_m) before those floating
  // over it: a flange's neck seen without its rim fits a pipe as well, but the pipe would hang
  // in the water over the seabed.
  double score_tie = 0.02;
  // When the best verified candidate scores below this, the segment may hold a smaller object
  // and something touching it: the other objects within max_chi_square are posed too, whatever
  // their size and chi-square rank. In the recognition bench's 100 scans one answer scored under
  // 0.85 (a tee, 0.65, on a pipe and a flange touching end to end: the pipe is now recognised).
  // When none is verified, the others the segment's size fits are posed before it is split: the
  // ESF of a partial view can rank its object past max_chi_square_ratio (on the bench's two
  // 100-scan sets, an elbow of seed 1 and a flange and an elbow of seed 2 that were "unknown" are
  // recognised), each from its nearest view only (unverified_pose_views).
  double weak_score = 0.85;
  // pose_views for the others posed when none of the chosen is verified: with 1, the same answers
  // but one wrong one as with 4, for about 0.015 s per scan instead of 0.06. In [0, 64].
  int unverified_pose_views = 1;
  // A segment no single object explains may be several touching each other: the object that
  // explains the largest part of it (at least this share of its points) is taken out and the
  // rest recognised again, as is what a recognised object leaves unexplained; at most
  // max_objects_per_segment objects come out of one segment. A part is verified as any
  // candidate is.
  double min_part_share = 0.25;
  int max_objects_per_segment = 3;
  // Objects posed on each half of such a segment, nearest by chi-square first (at most
  // max_candidates). In the recognition bench's 100 scans, of 26 segments split, the part came
  // from a half's nearest object 11 times, its second 4 times, its third never: 2 gives the same
  // answers in two thirds of the time (0.04 s per scan less).
  int split_candidates = 2;
  // A pose direction is free when the final ICP pins it to no better than this standard
  // deviation (its point-to-plane residual over the square root of its information; a
  // rotation's at the object's radius), metres: what a grasp cannot take as known.
  double free_direction_std_m = 0.002;
  // The phase about an N-fold symmetry axis (N >= 3) is free when no turn over a period puts this
  // many more points' worth of truncated residual off the model (SymmetryPhasePinned), points.
  // On the recognition bench's 18 flanges the spread was 1-4 where the bolts were not in view
  // (two of them posed 14 and 19 degrees off) and 6-112 where they were.
  double min_phase_points = 5.0;
  // Residuals within a cube of this side are taken as correlated (one misfit: a bolt head, a
  // facet), independent from cube to cube, for the pose covariance (ResidualPatchSpread), metres.
  // On the recognition bench's 109 poses within 10 degrees, the median NEES per pinned direction
  // was 10.6 at 2 cm, 5.2 at 5 cm, 4.1 at 10 cm (1 when consistent; 10 cm leaves a few cubes on
  // an object); the same poses, the same answers.
  double residual_patch_m = 0.05;
  // The pose covariance's floor: a standard deviation added along every pinned direction (a
  // rotation's at the object's radius), for what no residual shows, the model's and the segment's
  // sampling at the voxel, metres. Without it, the median NEES per pinned direction was 5.0 over
  // the recognition bench's 116 poses within 10 degrees and 5 cm (8.8 over 66 on another 60
  // scans, seed 2); with 0.1 mm, 0.89 (0.97 on those, which were not used to choose it).
  double pose_floor_std_m = 0.0001;
  // The fine ICP restarted from the answer moved this many database voxels each way along every
  // direction it pins (a rotation's at the object's radius), where it comes to rest added to the
  // pose covariance (RestartSpread); 0 = not restarted. It shows where the fit is flatter than
  // its information says: a pipe whose slide only an end's few points pin, a model taught from a
  // scan whose symmetric halves differ. One voxel is the scale the fine ICP pairs points at (its
  // stages reach 4, 2 and 1.5 voxels; bench/recognition/RESULTS.md has the steps tried).
  double pose_restart_voxels = 1.0;
  std::uint64_t seed = 1;
  int threads = 0;     // OpenMP threads, 0 = OpenMP's default; the answer does not depend on it
  void Check() const;  // throws uwscan::Error naming the field
};

// One object considered for a segment.
struct RecognitionCandidate {
  std::string object_id;
  double chi_square = 0.0;  // to its nearest view
  int view = -1;            // that view's index in the object's views
  double fitness = 0.0;     // share of the segment on the posed model
  double close = 0.0;       // share of the segment within close_distance_m of its surface
  double missing = 1.0;     // share of the surface it should have seen that the sensor saw through
  double buried = 0.0;      // share of the model beyond a support plane (SupportContact)
  double clearance_m =
      std::numeric_limits<double>::infinity();  // over the support planes (SupportContact)
  double rmse_m = 0.0;                          // point-to-plane RMS of the final ICP
  double score =
      0.0;  // close x (1 - missing) x (1 - buried); the best verified one wins (score_tie)
  bool verified = false;
  Eigen::Isometry3d T_S_O = Eigen::Isometry3d::Identity();
};

struct RecognizedObject {
  std::string object_id;  // "unknown" when nothing matched well enough
  double score = 0.0;
  double chi_square = 0.0;
  double margin = 0.0;  // chi-square of the best other object's nearest view minus this one's
  Eigen::Isometry3d T_S_O = Eigen::Isometry3d::Identity();  // pose in the scan frame
  // Covariance of the pose over [w (rad), v (m)] in the object frame: the object moved by
  // x -> x + w x (x - c) + v, c the model's centroid; from the ICP's information, its
  // point-to-plane residual and how its residuals spread over residual_patch_m cubes
  // (AnalysePoseConstraints). Free directions carry none (0 there).
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  std::vector<FreeDirection> free_directions;
  // Other poses of this object that fit the scan as well (verified, scoring within score_tie)
  // and are not the same modulo its symmetries: what the scan cannot tell apart, such as a
  // valve's body turned half a turn about its stem while its handle is out of the sweep, or a
  // tee turned about its run while its branch is. T_S_O each; empty when the pose is unique.
  std::vector<Eigen::Isometry3d> equivalent_poses_S;
  // Other objects that explain the segment as well (verified, scoring within score_tie of the
  // best): what the scan cannot tell apart, such as a lever valve and a wheel valve whose handle
  // the sweep did not reach, or a pipe and a tee whose branch it did not. The answer is the one
  // whose views the segment resembles most (chi-square). Each with its pose T_S_O; empty when
  // the identity is clear.
  std::vector<std::pair<std::string, Eigen::Isometry3d>> equivalent_objects_S;
  std::vector<std::pair<std::string, Eigen::Isometry3d>> grasps_S;  // name, T_S_G
  std::vector<RecognitionCandidate> candidates;  // every object considered, best first
  std::vector<std::size_t> segment;              // indices into the input scan
  Eigen::Vector3d centroid_S = Eigen::Vector3d::Zero();
};

struct RecognitionResult {
  // One per segment, largest segment first, then the parts split off segments in that order.
  std::vector<RecognizedObject> objects;
  std::size_t plane_points = 0;  // removed as planes
  // preprocess, segment, describe, match, then the pose: coarse (starts), sift, refine, final,
  // free (the accepted pose along the directions its fit leaves free);
  // equivalents (other poses that fit as well); split (a segment no object explains searched
  // for the objects it holds: its own poses are not counted in coarse to final); verify; join
  // (neighbouring segments one object may explain together, each stage of theirs included)
  std::map<std::string, double> stage_seconds;
};

// Plane removal (RemoveSupportPlanes), Euclidean segments, ESF against every view by chi-square,
// then for the best few objects a pose: starts from FPFH + RANSAC (correspondences restricted to
// the model surface the matched view saw) and from the nearest views rolled about the line of
// sight, sifted by a short ICP, the best refined by point-to-plane ICP of the segment onto the
// whole model and verified by fit and by model surface that should have been seen. A segment no
// object explains is searched for the object explaining the largest part of it (each of its
// halves recognised as a segment for pose candidates), which is taken out, and the rest is
// recognised again; so is what a recognised object leaves unexplained. The scan is in the
// sensor's frame (the sensor at its origin), metres. Deterministic for any thread count. Throws
// uwscan::Error on an invalid scan (NaN) or options.
RecognitionResult RecognizeObjects(const PointCloud& scan, const ObjectDatabase& db,
                                   const RecognitionOptions& options = {});

// The same, keeping what it derives from the database (its views' features, its models' search
// structures) in `cache` for the next scans: the answer is the same, only faster. Throws
// uwscan::Error when `cache` was made for another database.
class RecognitionCache;
RecognitionResult RecognizeObjects(const PointCloud& scan, const ObjectDatabase& db,
                                   RecognitionCache& cache, const RecognitionOptions& options = {});

}  // namespace uwscan::perception
