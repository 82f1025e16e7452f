#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "perception/cloud/point_cloud.hpp"

namespace uwscan::perception {

// What ReadCloud found in a file besides the cloud.
struct CloudReadStats {
  std::size_t num_in_file = 0;             // points (vertices) the file holds
  std::size_t num_dropped_non_finite = 0;  // dropped: a NaN or infinite coordinate, or a normal
                                           // that is not finite or has zero length
  bool has_normals = false;                // normals were read (PCD normal_x.., PLY nx..)
  // The file's row (0-based point or vertex) of each point of the cloud: what an index into the
  // cloud is in the file once points were dropped.
  std::vector<std::size_t> rows;
  // The sensor's pose in the file's frame, in the file's units, when the file says it (a PCD
  // VIEWPOINT line).
  std::optional<Eigen::Isometry3d> T_file_sensor;
  std::string viewpoint_error;  // why the file's VIEWPOINT cannot be used (empty: none)
};

// Reads a point cloud from .pcd (uwscan's bounded reader; ascii, binary and binary_compressed),
// .ply (uwscan's bounded reader; vertices only, faces ignored) or .xyz (text: one point per
// line, the first three numbers are x y z in metres, further columns ignored; blank lines and
// lines starting with '#' skipped). Files hold absolute coordinates (float or double); the
// cloud's origin is put at their centroid, computed in double, so the float offsets stay small.
// Normals and intensities are read when the file has them (not from .xyz).
// Points with a non-finite coordinate or normal are dropped and counted in `stats`.
// Throws uwscan::Error naming the file when it does not exist, its extension is not one of
// these, it cannot be parsed, has no x/y/z, or holds no finite point.
PointCloud ReadCloud(const std::filesystem::path& path, CloudReadStats* stats = nullptr);

// Writes a cloud to .ply or .pcd (binary, or ascii when `binary` is false) in absolute
// coordinates: float32 while every coordinate is below 10 m in magnitude (rounding under
// 0.5 um), float64 beyond, so clouds far from the frame origin keep their precision. Normals are
// written when present (PLY nx ny nz, PCD normal_x normal_y normal_z), and so are intensities
// (float32 "intensity"). PCD goes through PCL's
// PCDWriter; PLY is written by uwscan (PCL 1.13's PLYWriter prints ASCII values to 6 digits).
// Atomic: the file is written beside the target under a temporary name and renamed over it,
// so an existing file stays intact and readable when writing fails. `T_file_sensor`, the
// sensor's pose in the file's frame, goes into a PCD's VIEWPOINT line (identity when unset; PCL
// writes it with six significant digits, so a pose hundreds of metres from the file's origin
// keeps only millimetres to centimetres).
// Throws uwscan::Error naming the file on an unsupported extension, an empty or non-finite cloud,
// a sensor pose for a PLY (which has no place for it), or an I/O failure.
void WriteCloud(const std::filesystem::path& path, const PointCloud& cloud, bool binary = true,
                const std::optional<Eigen::Isometry3d>& T_file_sensor = std::nullopt);

}  // namespace uwscan::perception
