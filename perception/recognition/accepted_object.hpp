#pragma once
// Internal to RecognizeObjects (object_recognizer.cpp), not the library's interface: the verified
// candidates of a segment ranked, and the one chosen made an answer (identity, pose, free
// directions, covariance, grasps).

#include <Eigen/Geometry>
#include <string>
#include <utility>
#include <vector>

#include "perception/cloud/point_cloud.hpp"
#include "perception/recognition/object_database.hpp"
#include "perception/recognition/object_recognizer.hpp"
#include "perception/recognition/recognition_verification.hpp"
#include "perception/recognition/segment_pose.hpp"

namespace uwscan::perception::recognition {

// Verified candidates within `tie` of the best score told apart: resting on a support plane
// (within `resting_m`) first, then the lower chi-square. The pick is moved to the front.
void BreakTie(double tie, double resting_m, std::vector<PosedObject>& ranked);

// The verified candidates that could still rank first placed along the directions their fits
// leave free (turned a half turn first when they miss surface), before they are ranked.
void PlaceContendersAlongFreeDirections(const PointCloud& segment, const SceneAround& around,
                                        const ScanContext& ctx, std::vector<PosedObject>& posed);

// The other verified objects BreakTie chose among: scoring within `tie` of the best score.
std::vector<std::pair<std::string, Eigen::Isometry3d>> EquivalentObjects(
    const std::vector<PosedObject>& ranked, double tie);

// `object` filled from the chosen candidate: identity, pose, margin to `other_chi_square`, the
// model's symmetries and the directions and phases the fit on `fitted` leaves free (scan frame),
// the covariance over the rest, and the grasps. `fitted` is the cloud posed.fine was fitted on,
// with its normals (the covariance's restarts run that fit again).
void Accept(const PosedObject& posed, const PointCloud& fitted, const ObjectModel& model,
            double other_chi_square, const ScanContext& ctx, RecognizedObject& object);

}  // namespace uwscan::perception::recognition
