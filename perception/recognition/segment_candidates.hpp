#pragma once
// Internal to RecognizeObjects (object_recognizer.cpp), not the library's interface: which objects
// of the database are worth posing on a segment, and one of them posed there.

#include <Eigen/Geometry>
#include <cstddef>
#include <utility>
#include <vector>

#include "perception/cloud/nearest_grid.hpp"
#include "perception/cloud/point_cloud.hpp"
#include "perception/features/esf.hpp"
#include "perception/recognition/object_database.hpp"
#include "perception/recognition/segment_pose.hpp"

namespace uwscan::perception::recognition {

// The `count` nearest views of each object by chi-square, nearest first: (distance, view index).
std::vector<std::vector<std::pair<double, int>>> NearestViews(const EsfDescriptor& esf,
                                                              const ObjectDatabase& db, int count);

// The objects worth posing on a segment: up to max_candidates whose nearest view is within
// max_chi_square (and within max_chi_square_ratio of the best object's) and that are not smaller
// than the segment's own cluster (a bounding-box diagonal can exceed it by up to sqrt(3); debris
// that joined it may lie beyond the object), nearest first, with their nearest views.
struct ChosenObjects {
  std::vector<std::size_t> objects;
  // The others within max_chi_square, nearest first, whatever their size: posed only when the
  // chosen explain the segment poorly (it may hold one of them and something else)...
  std::vector<std::size_t> others;
  // ...and those of them the segment's size fits: posed when none of the chosen is verified.
  std::vector<std::size_t> others_that_fit;
  std::vector<std::vector<std::pair<double, int>>> nearest_views;  // of every object
  std::vector<double> nearest_chi_square;                          // of every object
};
ChosenObjects ChooseObjects(const EsfDescriptor& esf, double extent_m, const ScanContext& ctx);

// Object `i` posed on a segment from its starts (PoseStarts), with its chi-square and view.
PosedObject PoseCandidate(const DescribedSegment& s, std::size_t i, const ChosenObjects& chosen,
                          const SceneAround& around, const ScanContext& ctx);

// The points of `segment` within `distance_m` (at most model_grid's radius) of the posed model's
// surface points.
std::vector<std::size_t> PointsOnModel(const PointCloud& segment, const ObjectModel& model,
                                       const NearestGrid& model_grid,
                                       const Eigen::Isometry3d& T_O_S, double distance_m);

}  // namespace uwscan::perception::recognition
