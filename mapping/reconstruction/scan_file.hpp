#pragma once

#include <cstddef>
#include <filesystem>
#include <vector>

#include "mapping/reconstruction/reconstruction.hpp"
#include "perception/cloud/point_cloud.hpp"

namespace uwscan::mapping {

// A scan as recognition takes it, in the sensor's frame, and where each of its points is in the
// file it came from.
struct ScanFile {
  perception::PointCloud cloud;
  // The row of each point of `cloud` in the file: a cloud file's points with a NaN or infinite
  // coordinate are dropped, so a point's index in `cloud` is not its row there; a log's points
  // are numbered in the order they are triangulated. What a report gives to other tools.
  std::vector<std::size_t> rows;
  std::size_t rows_in_file = 0;
};

// Reads a scan: a cloud file (.ply .pcd .xyz), or one sweep of a dive log triangulated with
// `options` (its use_navigation and relative_to_middle are set here): each frame placed with the
// log's navigation at its own time when it has some, the points in the camera frame at the
// sweep's middle, so a sweep taken while the vehicle moved is not smeared; without navigation
// the frames are taken as seen from a scanner at rest. A log of several sweeps needs
// options.sweep. The same file gives the same points in the same order, so indices into a scan
// (a recognition report's segments) stay valid. Throws uwscan::Error naming the file when it
// cannot be read, a log holds several sweeps and none is chosen, the sweep chosen is not in it or
// holds no triangulated point, or a sweep is chosen for a cloud file.
ScanFile ReadScanFile(const std::filesystem::path& path, ReconstructionOptions options = {});

}  // namespace uwscan::mapping
