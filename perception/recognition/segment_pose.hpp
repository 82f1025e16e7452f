#pragma once
// Internal to RecognizeObjects (object_recognizer.cpp), not the library's interface: one object
// posed on a segment of a scan and verified there, and the other poses that fit it as well.

#include <Eigen/Geometry>
#include <chrono>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/cloud/point_cloud.hpp"
#include "perception/features/fpfh.hpp"
#include "perception/recognition/object_database.hpp"
#include "perception/recognition/object_pose_search.hpp"
#include "perception/recognition/object_recognizer.hpp"
#include "perception/recognition/recognition_verification.hpp"
#include "perception/registration/icp.hpp"

namespace uwscan::perception::recognition {

// Seconds per stage, added up across calls.
class StageClock {
 public:
  explicit StageClock(std::map<std::string, double>& seconds) : seconds_(seconds) {}
  void Lap(const std::string& stage) {
    const auto now = std::chrono::steady_clock::now();
    seconds_[stage] += std::chrono::duration<double>(now - last_).count();
    last_ = now;
  }

 private:
  std::map<std::string, double>& seconds_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// What every segment of one scan is recognised against.
struct ScanContext {
  const ObjectDatabase& db;
  const RecognitionOptions& options;
  RecognitionCache& cache;
  const PointCloud& down;  // the voxelised scan, planes included
  const KnnIndex& down_index;
  const std::vector<DetectedPlane>& planes;  // removed from `down` (the seabed), inliers into it
  StageClock& clock;
};

// The context of one task of a parallel loop over a scan's work: one thread, and a clock of its
// own, untimed (the caller times the whole loop; a clock is not shared between threads).
class OneThreadContext {
 public:
  explicit OneThreadContext(const ScanContext& outer)
      : options_(OneThread(outer.options)),
        clock_(untimed_),
        ctx_{outer.db, options_, outer.cache, outer.down, outer.down_index, outer.planes, clock_} {}
  OneThreadContext(const OneThreadContext&) = delete;  // ctx_ refers to the members beside it
  OneThreadContext& operator=(const OneThreadContext&) = delete;
  const ScanContext& ctx() const { return ctx_; }

 private:
  static RecognitionOptions OneThread(RecognitionOptions options) {
    options.threads = 1;
    return options;
  }
  RecognitionOptions options_;  // initialised in this order: each refers to those above it
  std::map<std::string, double> untimed_;
  StageClock clock_;
  ScanContext ctx_;
};

// A segment's voxelised points with normals (scan frame) and FPFH at every one.
struct DescribedSegment {
  PointCloud cloud;
  FpfhFeatures features;
};
DescribedSegment DescribeSegment(const PointCloud& segment, const ScanContext& ctx);

// One object posed on (part of) a segment, with the fine ICP that placed it.
struct PosedObject {
  std::size_t object = 0;
  RecognitionCandidate candidate;
  RegistrationResult fine;
};

// What the scan saw around `segment`, for the verification: over its window of directions widened
// by half the database's largest object, so that a posed model reaching out of its segment (a
// tee's branch, a flange's rim, a handwheel cut off by its own shadow) is checked there too.
SceneAround SceneAroundOf(const PointCloud& segment, const ScanContext& ctx);

// The posed model verified on `segment`: fit, closeness, missing surface, and how it meets the
// support planes around it (buried share, clearance).
void Verify(const PointCloud& segment, const ObjectModel& model, const NearestGrid& model_grid,
            const SceneAround& around, const RegistrationResult& refined, const ScanContext& ctx,
            RecognitionCandidate& c);

// Verified beats unverified, then the higher score; ties keep the earlier.
bool Better(const RecognitionCandidate& a, const RecognitionCandidate& b);

// Every k-th point of a cloud, at most about `count` of them.
PointCloud Strided(const PointCloud& cloud, std::size_t count);

// An object's best pose on the whole segment from `starts`: sifted, the best few refined by the
// fine ICP on refine_points of the segment's points and verified on all of them; the winner's
// phase about any N-fold axis is searched, then it is refined once more on all its points (the
// pose barely moves, but its information is that of every point) and verified again.
PosedObject PoseOnSegment(const DescribedSegment& s, std::size_t object,
                          const std::vector<Eigen::Isometry3d>& starts, const SceneAround& around,
                          const ScanContext& ctx);

// The accepted pose moved along each direction its fit leaves free to where the model leaves the
// fewest points unexplained: surface the sensor saw through plus segment points off its surface.
// A pipe seen without one of its ends slides along its axis (point-to-plane pairs on its wall do
// not pin it), and the end the scan shows pins the slide: slid past it, the model lies where lines
// of sight went on to the seabed; slid short of it, the segment's last points leave the model.
// An elbow seen without its ends turns about its bend axis alike. Offsets (a turn's as its arc at
// the model's radius) over the radius each way for a slide and an eighth of a turn each way for a
// turn, every 2 voxels, then every half voxel over 3 voxels each way about the best, the count
// smoothed over three of them (SmoothedMinimum); the pose moves only when that explains at least
// 10 points (and 2 % of the segment) more than where the fit left it (with neither end in view a
// pipe explains as much all along, give or take a few points), then is refined by the last stage
// of the fine ICP and stands if still verified. For every candidate that could still rank first,
// before they are ranked (RecognizeSegment): left unplaced, a pipe seen with one end lost to a
// tee or flange fitting the same stretch. The directions stay reported free: the fit does not pin
// them, the verification's counts do, to about a voxel. `segment` needs its normals (the fine ICP's
// normal gate).
void PlaceAlongFreeDirections(const PointCloud& segment, const SceneAround& around,
                              const ScanContext& ctx, PosedObject& posed);

// The posed object turned by each of DistinctHalfTurns, refined by the fine ICP and verified, and
// moved to the best of them when that scores better (Better): a candidate that fits the segment
// but leaves model surface where the sensor saw through may be posed a half turn off (a tee seen
// as an L, turned about the L's bisector, its branch out where the seabed was seen). `segment`
// needs its normals (the fine ICP's normal gate).
void TurnToBetterHalfTurn(const PointCloud& segment, const SceneAround& around,
                          const ScanContext& ctx, PosedObject& posed);

// Other poses of a posed object the scan cannot tell from its own (RecognizedObject::
// equivalent_poses_S): its pose turned by each of DistinctHalfTurns (a nearly symmetric object,
// a valve's body, fits either way; a tee seen as an L fits turned about the L's bisector), refined
// by the fine ICP and verified like it; kept when verified, scoring within score_tie of it and more
// than 5 degrees or 2 voxels from it and from each other modulo the object's symmetries. T_S_O
// each.
std::vector<Eigen::Isometry3d> EquivalentPoses(const DescribedSegment& s, const PosedObject& posed,
                                               const SceneAround& around, const ScanContext& ctx);

}  // namespace uwscan::perception::recognition
