#pragma once

#include <nlohmann/json.hpp>

#include "perception/recognition/object_recognizer.hpp"

namespace uwscan::app {

// The recognition report `uwscan recognize --json` writes ({"uwscan_format": 1, "kind":
// "recognition_report"}): the scan's point count, then per segment the id ("unknown" when none
// was verified), its points (indices into the scan), score, chi-square and margin, pose T_S_O
// (4x4, position, quaternion xyzw), covariance and standard deviations over [w (rad), v (m)]
// in the object frame, free directions, grasp poses and the candidates. The caller adds
// "scan" and "database" (paths relative to the report's folder), which `uwscan view` reads.
nlohmann::json RecognitionJson(const perception::RecognitionResult& result, std::size_t scan_points);

}  // namespace uwscan::app
