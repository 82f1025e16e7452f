#pragma once

#include <nlohmann/json.hpp>

#include "perception/object_recognizer.hpp"

namespace uwscan::app {

// The recognition report `uwscan recognize --json` writes (format "uwscan_recognition": 1):
// per segment the id ("unknown" when none was verified), score, chi-square and margin, pose
// T_S_O (4x4, position, quaternion xyzw), covariance and standard deviations over
// [w (rad), v (m)] in the object frame, free directions, grasp poses and the candidates.
nlohmann::json RecognitionJson(const perception::RecognitionResult& result);

}  // namespace uwscan::app
