#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace uwscan::perception {

// The points of a PCD file (and its normals when it has normal_x/y/z or nx/ny/nz, and its
// intensities), as read.
struct PcdContent {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;  // one per point, or empty
  std::vector<double> intensity;         // one per point when it has an intensity field, or empty
  // The sensor's pose in the file's frame from a VIEWPOINT line ("tx ty tz qw qx qy qz"), in the
  // file's units; unset when the header has none.
  std::optional<Eigen::Isometry3d> T_file_sensor;
  std::string viewpoint_error;  // why the VIEWPOINT line cannot be used (empty: none)
};

// Reads PCD 0.7 (and older headers without VERSION or COUNT) in ascii, binary and
// binary_compressed form, organised or not, with fields of any of PCL's types. uwscan's own
// bounded reader: sizes and counts are checked against the file before anything is allocated,
// and nothing is printed (PCL 1.13's reader segfaults on empty or header-less files and prints
// on every bad one). binary_compressed data is inflated by PCL's LZF routine, which checks its
// bounds. Values are kept as read (NaN included). Throws uwscan::Error naming the file and
// what is wrong.
PcdContent ReadPcd(const std::filesystem::path& path);

}  // namespace uwscan::perception
