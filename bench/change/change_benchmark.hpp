#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "bench/progress.hpp"

namespace uwscan::bench {

// What the inspection found, against the truth: two surveys of one structure (simulated dives,
// SLAM maps) with changes of known depth between them, compared by uwscan and by the peers on
// the same maps in one run.
struct ChangeBenchOptions {
  std::filesystem::path before_scene;  // data/scenes/change_before.yaml
  std::filesystem::path after_scene;   // data/scenes/change_after.yaml
  bool run_cloudcompare = true;        // when CloudCompare is installed
  std::filesystem::path table_cache;
  int threads = 2;
  void Check() const;
};

struct DepthFigures {
  int changes = 0;                // changes of this depth the method has points on
  double detection_rate = 0.0;    // of those, found (half their points or more)
  double false_area_share = 0.0;  // the method's false area, as for every depth
};

// One method's figures. Every method is judged by the same rule on points 1 cm apart: a change
// is detected when at least half of its surface points lie in significant regions of the right
// sign (unsigned methods: any); false area is the unchanged surface inside significant regions
// (groups of at least RegionOptions' size).
struct ChangeOutcome {
  std::string name;    // the scene object's
  int points = 0;      // the method's points on it
  double found = 0.0;  // share of them in significant regions of the right sign
};

struct MethodFigures {
  std::map<int, DepthFigures> by_depth_mm;
  std::vector<ChangeOutcome> changes;
  double unchanged_flagged_share = 0.0;  // unchanged points flagged, grouped or not
  double unchanged_rms_m = 0.0;          // RMS of its distance where nothing changed
  double changed_rms_error_m = 0.0;      // RMS of its distance less the true one on the changes
  std::optional<double> threshold_m;     // the threshold a plain distance was cut at
  double seconds = 0.0;                  // the comparison alone, files and start-up excluded
};

struct ChangeFigures {
  std::map<std::string, MethodFigures> methods;
  double map_rms_m = 0.0;  // the two maps' RMS distance to their true surfaces
  double simulate_seconds = 0.0, map_seconds = 0.0;
  bool cloudcompare_ran = false;
};

ChangeFigures RunChangeBench(const ChangeBenchOptions& options, const Progress& progress = {});

}  // namespace uwscan::bench
