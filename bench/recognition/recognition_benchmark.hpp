#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "bench/progress.hpp"
#include "perception/recognition/object_recognizer.hpp"

namespace uwscan::bench {

// Object recognition for grasping on simulated scans: the six procedural IMR objects in a
// database made by the virtual scanner, scenes of one or two of them on a seabed with a
// foreign mesh beside them (sometimes touching), each scanned once by the galvanometer scanner
// from 0.5-1.5 m, under water, with the image stages on. uwscan's recogniser and two peers
// on the same segments.
struct RecognitionBenchOptions {
  int scans = 100;        // scenes, each scanned once, >= 1
  std::vector<int> only;  // when not empty, only these scenes of the `scans` (to look at a case)
  int views = 24;         // database views per object, >= 1
  bool images = true;     // render and detect frames (else exact peaks + 0.1 px noise)
  int galvo_stride = 2;   // mirror steps per frame, >= 1 (2: 101 frames per sweep)
  std::uint64_t seed = 1;
  int threads = 2;
  bool run_peers = true;
  // OpenCV's PPF among the peers. Its match (OpenCV 4.6, Debian 12) can loop without end in
  // its hash table on some segments (over 8 min of CPU on one, seen twice), so it can be left out.
  bool run_ppf = true;
  std::filesystem::path data_cache;   // foreign meshes (scripts/fetch_data.sh)
  std::filesystem::path table_cache;  // cone table kept between runs
  // Simulated scans kept between runs (recognition_scan_cache.hpp) when not empty: simulation time
  // then counts reading them.
  std::filesystem::path scan_cache;
  void Check() const;
};

struct PipelineFigures {
  int objects = 0;     // catalogue objects in the scans (the rate's denominator)
  int recognised = 0;  // with the right id
  // ...or with another id, but the right one among the objects the answer reports fit as well
  // (equivalent_objects_S; peers report none: the same as recognised)
  int recognised_or_reported = 0;
  int pose_success = 0;  // of those: within 5 mm and 2 degrees modulo symmetry
  // ...or wrong only in what the answer says it cannot tell: one of its equivalent poses is
  // within 5 mm and 2 degrees, or the pose is once its reported free slides are left out and it
  // is turned about one of its reported free rotation axes (peers report neither: the same as
  // pose_success)
  int pose_or_reported = 0;
  int mssd_success = 0;                  // of those: MSSD below 0.1 x diameter
  int grasp_success = 0;                 // of those: grasp within 5 mm and 3 degrees
  int foreign = 0, foreign_unknown = 0;  // foreign meshes, and those called "unknown"
  double seconds = 0.0;              // recognition of every scan (segmentation included for uwscan)
  std::vector<double> scan_seconds;  // uwscan only: each scan's time (its tail, not just the mean)
  std::vector<double> rotation_errors_rad, translation_errors_m, grasp_position_errors_m,
      grasp_angle_errors_rad;
  // uwscan's reported pose covariance against its error (modulo symmetry): the NEES over the
  // directions the answer pins, divided by their number (1 for a consistent covariance), for
  // each recognised object within 10 degrees and 5 cm (gross errors, such as a half turn of a
  // valve whose handle is out of view, are no covariance's business). Peers report none.
  std::vector<double> pose_nees_per_dimension;
  std::map<std::string, std::vector<double>> pose_nees_by_class;  // the same, by true class
  // true class (or "foreign") -> answer -> count
  std::map<std::string, std::map<std::string, int>> confusion;
};

// What uwscan made of one object of one scan, for reading failures one by one.
struct ObjectOutcome {
  int scan = 0;
  std::string truth;          // catalogue id or "foreign"
  std::string answer;         // uwscan's id or "unknown"
  int points = 0;             // scan points on the object
  int points_in_segment = 0;  // of those, in the segment uwscan answered for it
  int segment_points = 0;     // scan points in that segment
  double rotation_error_rad = -1.0, translation_error_m = -1.0;  // modulo symmetry; -1: no pose
  std::vector<perception::RecognitionCandidate> candidates;      // uwscan's, best first
  int equivalent_poses = 0;                     // other poses uwscan reported as fitting as well
  std::vector<std::string> equivalent_objects;  // other objects uwscan reported as fitting as well
  int free_slides = 0, free_turns = 0;  // directions uwscan reported unconstrained by the scan
  // Per candidate of the true object, its pose error modulo symmetry (rotation rad, translation
  // m): a pose search that missed tells apart from a verification that refused; -1 for others.
  std::vector<std::pair<double, double>> candidate_errors;
  // Why a catalogue object was not recognised, from the true object posed at its true pose on the
  // segment answered for it (CheckObjectPose, refined and verified as recognition's candidates
  // are): "tie" (it verifies and scores within score_tie of the answer: the scan cannot tell the
  // two apart, and the answer went by chi-square), "missed" (it verifies and scores above the
  // answer, or the answer is "unknown": the pose search did not find it), "outscored" (it
  // verifies, the answer scores higher), "unverified" (it does not verify on that segment),
  // "no segment" (no segment holds its points); empty when recognised, and for foreign meshes.
  std::string why_wrong;
  std::optional<perception::RecognitionCandidate> truth_check;  // that check, when made
};

struct RecognitionBenchResult {
  int scans = 0;
  double database_seconds = 0.0;
  double simulation_seconds = 0.0;
  std::vector<std::string> object_ids;  // the database's objects, the answers a pipeline can give
  std::map<std::string, PipelineFigures> pipelines;    // uwscan, pcl_esf, opencv_ppf
  std::map<std::string, double> uwscan_stage_seconds;  // summed over scans
  double ppf_training_seconds = 0.0;
  std::vector<ObjectOutcome> outcomes;  // uwscan's, in scan order
};

RecognitionBenchResult RunRecognitionBench(const RecognitionBenchOptions& options,
                                           const Progress& progress = {});

}  // namespace uwscan::bench
