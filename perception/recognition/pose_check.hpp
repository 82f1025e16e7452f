#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <string>
#include <vector>

#include "perception/cloud/point_cloud.hpp"
#include "perception/recognition/object_database.hpp"
#include "perception/recognition/object_recognizer.hpp"

namespace uwscan::perception {

class RecognitionCache;

// A pose of a database object, given from outside (a layout drawing, the previous scan, a
// simulation's truth), checked on part of a scan as recognition checks its own candidates: the
// same voxel grid and support planes; the pose as given and as refined from it by the pose
// search's fine ICP, each verified by fit, closeness, missing surface and support contact, and the
// better of the two returned (RecognitionCandidate: verified, score). It answers whether the scan
// supports that object there as well as it supports what recognition answered: a recognition
// bench uses it to tell a scan that cannot decide between two objects from a search that missed.
//
// `segment`: indices into `scan` (RecognizedObject::segment). `object_id` must be in `db`.
// Throws uwscan::Error on an invalid scan or options, an unknown object, an empty segment, an
// index out of range or a pose that is not rigid.
RecognitionCandidate CheckObjectPose(const PointCloud& scan,
                                     const std::vector<std::size_t>& segment,
                                     const ObjectDatabase& db, RecognitionCache& cache,
                                     const std::string& object_id, const Eigen::Isometry3d& T_S_O,
                                     const RecognitionOptions& options = {});

}  // namespace uwscan::perception
