#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "perception/recognition/object_database.hpp"
#include "perception/recognition/object_recognizer.hpp"
#include "perception/recognition/object_symmetry.hpp"

// Whether a wrong pose is wrong only in what its answer says it cannot tell (issue 50, item 6:
// an honest answer reports its ambiguity). Shared by the recognition bench and its conditions.
namespace uwscan::bench {

// Whether a pose off the truth is right, within 5 mm and 2 degrees, but for what its answer
// reports it cannot tell: modulo the symmetries its model carries (`model.symmetries`, declared
// or found by the database), through one of its equivalent poses, once the translation along its
// reported free slides is left out, or once it is turned about one of its reported free rotation
// axes (searched by the degree over a full turn). `e` is the pose's error modulo those same
// symmetries; `points` the model points the error is measured on (object frame).
bool PosedButForWhatIsReported(const perception::SymmetricPoseError& e,
                               const Eigen::Isometry3d& T_S_O, const Eigen::Isometry3d& T_S_O_true,
                               const std::vector<Eigen::Vector3d>& points,
                               const perception::ObjectModel& model,
                               const perception::RecognizedObject& reported);

}  // namespace uwscan::bench
