#pragma once

#include <filesystem>

#include "mapping/reconstruction/reconstruction.hpp"
#include "perception/cloud/point_cloud.hpp"

namespace uwscan::mapping {

// A scan as recognition takes it, in the sensor's frame: a cloud file (.ply .pcd .xyz), or a
// dive log of one static sweep triangulated in the camera frame (navigation ignored, the sensor
// at the origin). `options` choose the triangulation of a log; its use_navigation is ignored.
// The same file gives the same points in the same order, so indices into a scan (a recognition
// report's segments) stay valid. Throws uwscan::Error naming the file when it cannot be read or
// a log holds no triangulated point.
perception::PointCloud ReadScanFile(const std::filesystem::path& path, ReconstructionOptions options = {});

}  // namespace uwscan::mapping
