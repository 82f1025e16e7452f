#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace uwscan::scanner {

// An indexed triangle mesh, metres, in the frame of the file it came from.
struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> triangles;  // vertex indices, counter-clockwise seen from outside

  double BoundingBoxDiagonal() const;
};

// Reads PLY, OFF, STL or OBJ through Assimp (triangulating polygons, merging duplicate
// vertices). Throws uwscan::Error naming the file when it is missing, unreadable or holds no
// triangles.
TriangleMesh LoadMesh(const std::filesystem::path& path);

// Points drawn uniformly over the surface (triangles picked by area), with the triangles'
// unit normals. Deterministic for a given seed.
struct SurfaceSamples {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;
};
SurfaceSamples SampleSurface(const TriangleMesh& mesh, int count, std::uint64_t seed);

}  // namespace uwscan::scanner
