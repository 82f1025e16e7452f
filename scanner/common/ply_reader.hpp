#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <vector>

namespace uwscan::scanner {

// What uwscan takes from a PLY file: the vertex element's positions (and normals and
// intensities), and the face element's polygons. Other elements and properties (colours,
// confidence, ...) are read past and dropped.
struct PlyContent {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3d> normals;  // one per vertex when it has nx ny nz, else empty
  // One per vertex when it has an intensity property ("intensity", or CloudCompare's
  // "scalar_intensity" / "scalar_Intensity"), in the file's units; else empty.
  std::vector<double> intensity;
  std::vector<Eigen::Vector3i> triangles;  // polygons fan-triangulated, indices checked
};

// Reads ascii, binary_little_endian and binary_big_endian PLY 1.0 with every scalar type
// (int8 .. float64, also by their old names char .. double) and list properties. uwscan's own
// bounded reader: every count is checked against the bytes left before anything is allocated,
// and nothing is printed (PCL 1.13's reader aborts on some broken headers and prints on every
// bad file). Values are kept as read: non-finite ones are the caller's to judge.
// Throws uwscan::Error naming the file and what is wrong (header line, element, row) when the
// file is missing, not PLY, has no vertex element with x, y and z, is cut short, or (with
// `faces`) has a polygon of fewer than 3 vertices or an index out of range.
PlyContent ReadPly(const std::filesystem::path& path, bool faces);

// The face count a PLY header declares (its "element face N" line), reading the header lines
// only; std::nullopt when it has no face element (a cloud) or cannot be read. N > 0: a mesh.
std::optional<long long> PlyFaceCount(const std::filesystem::path& path);

}  // namespace uwscan::scanner
