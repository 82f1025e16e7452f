#pragma once

#include <vector>

#include "mapping/change/change_regions.hpp"
#include "mapping/change/surface_deviation.hpp"
#include "mapping/change/survey.hpp"
#include "mapping/change/survey_alignment.hpp"

namespace uwscan::mapping {

struct CompareOptions {
  SurveyAlignmentOptions alignment;
  DeviationOptions deviation;
  RegionOptions regions;
  // With tiles, and where a survey carries its poses' joint uncertainty (a map report of this
  // version, or a dive mapped): how loosely it placed each point against the rest of its tile
  // adds to the level of detection (TileRelativePoseSigmas).
  bool joint_pose_uncertainty = true;
  // A point counts as seen from every pose at most this much farther from it than the nearest
  // pose: the submaps whose sweeps covered it (metres, >= 0). On the change bench's dives (the
  // galvanometer scanner 1 m over the seabed) 95 % of the submaps that put a point in a map
  // voxel lie within 0.39 m of that (bench/change/RESULTS.md).
  double seen_within_m = 0.4;
  void Check() const;
};

// How much of the reference's surface came out in each state, m^2 (core points x spacing^2).
struct SurfaceAreas {
  double unchanged_m2 = 0.0, changed_m2 = 0.0, not_inspected_m2 = 0.0;
  int core_points = 0;
};

// What an inspection found: the map against a reference (design model, earlier map or cloud).
struct SurveyComparison {
  SurveyAlignment alignment;
  std::vector<CoreDeviation> deviations;  // one per core point of the reference
  std::vector<int> region_of;             // each core point's region, -1 outside any
  std::vector<ChangeRegion> regions;      // largest first
  SurfaceAreas areas;
  double core_spacing_m = 0.0;
  // Whether the level of detection carries the surveys' pose covariances (the map registered
  // as a whole) or the tiles' registration covariances (tile by tile, which absorbs the slowly
  // varying pose errors the covariances describe).
  bool pose_covariances_used = false;
  // Whether, tile by tile, the level of detection also carries how loosely either survey placed
  // each point against the rest of its tile (its joint pose uncertainty known).
  bool joint_pose_uncertainty_used = false;
  double seconds = 0.0;
};

// The map aligned on the reference, the signed deviation and its level of detection at each
// core point, the significant ones grouped into regions. Throws uwscan::Error when either cloud
// is empty, their bounding boxes do not meet (other units or frames: the message says which
// sizes it saw), the registration finds no overlap, or the options are invalid.
SurveyComparison CompareSurveys(const Survey& map, const Survey& reference,
                                const CompareOptions& options);

}  // namespace uwscan::mapping
