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

// Reads PLY, OFF and STL through uwscan's bounded readers and OBJ through Assimp (polygons
// triangulated; STL's repeated vertices merged). Throws uwscan::Error naming the file when it
// is missing, unreadable, holds no triangles or a non-finite vertex.
TriangleMesh LoadMesh(const std::filesystem::path& path);

// Writes binary little-endian PLY (float32 x y z, int32 vertex indices), which LoadMesh and
// common mesh tools read. Atomic: the file is written next to `path` and renamed over it, so
// a reader never sees half a mesh. Throws uwscan::Error naming the file when the mesh is
// empty, has an index out of range or a non-finite vertex, or the file cannot be written.
void WriteMeshPly(const TriangleMesh& mesh, const std::filesystem::path& path);

// Points drawn uniformly over the surface (triangles picked by area), with the triangles'
// unit normals. Deterministic for a given seed.
struct SurfaceSamples {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;
};
SurfaceSamples SampleSurface(const TriangleMesh& mesh, int count, std::uint64_t seed);

// What a scan of all of the mesh's sides gives: `count` points over its surface (SampleSurface),
// each moved by Gaussian noise of sigma_m (>= 0) along every axis, the draws in sequence.
// Deterministic for a given seed.
std::vector<Eigen::Vector3d> ScannedSurface(const TriangleMesh& mesh, int count, double sigma_m,
                                            std::uint64_t seed);

}  // namespace uwscan::scanner
