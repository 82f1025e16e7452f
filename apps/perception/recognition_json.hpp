#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <vector>

#include "mapping/reconstruction/scan_file.hpp"
#include "perception/recognition/object_recognizer.hpp"

namespace uwscan::app {

// The recognition report `uwscan recognize --json` writes ({"uwscan_format": 1, "kind":
// "recognition_report"}): the scan file's row count ("scan_points"), then per segment the id
// ("unknown" when none was verified), its points (rows of the scan file: `rows[i]` is the row of
// the scan's point i, so points dropped on reading, e.g. NaN, leave no hole), score, chi-square
// and margin, pose T_S_O (4x4, position, quaternion xyzw), covariance and standard deviations
// over [w (rad), v (m)] in the object frame, free directions, grasp poses and the candidates;
// "scan_frame": how the file became the sensor frame S (its unit, where the sensor's pose came
// from, T_file_sensor in the file's units), and each pose in the file's frame and units too
// ("T_file_O").
// The caller adds "scan" and "database" (paths relative to the report's folder) and, for a
// sweep of a dive log, "scan_sweep", which `uwscan view` reads. Documented in
// perception/README.md.
nlohmann::json RecognitionJson(const perception::RecognitionResult& result,
                               const mapping::ScanFile& scan);

}  // namespace uwscan::app
