#include "scanner/triangle_mesh.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <assimp/Importer.hpp>
#include <random>

#include "scanner/error.hpp"

namespace uwscan::scanner {

double TriangleMesh::BoundingBoxDiagonal() const {
  if (vertices.empty()) return 0.0;
  Eigen::Vector3d lo = vertices.front(), hi = vertices.front();
  for (const Eigen::Vector3d& v : vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  return (hi - lo).norm();
}

TriangleMesh LoadMesh(const std::filesystem::path& path) {
  if (!std::filesystem::is_regular_file(path)) throw Error(path.string() + ": no such mesh file");
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(
      path.string(), aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                         aiProcess_DropNormals | aiProcess_FindDegenerates);
  if (scene == nullptr) {
    throw Error(path.string() + ": cannot read mesh: " + importer.GetErrorString());
  }
  TriangleMesh mesh;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* part = scene->mMeshes[m];
    const int base = static_cast<int>(mesh.vertices.size());
    for (unsigned v = 0; v < part->mNumVertices; ++v) {
      const aiVector3D& p = part->mVertices[v];
      mesh.vertices.emplace_back(p.x, p.y, p.z);
    }
    for (unsigned f = 0; f < part->mNumFaces; ++f) {
      const aiFace& face = part->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines left by the triangulation
      mesh.triangles.emplace_back(base + static_cast<int>(face.mIndices[0]),
                                  base + static_cast<int>(face.mIndices[1]),
                                  base + static_cast<int>(face.mIndices[2]));
    }
  }
  if (mesh.triangles.empty()) throw Error(path.string() + ": the mesh has no triangles");
  for (const Eigen::Vector3d& v : mesh.vertices) {
    if (!v.allFinite()) throw Error(path.string() + ": the mesh has a non-finite vertex");
  }
  return mesh;
}

SurfaceSamples SampleSurface(const TriangleMesh& mesh, int count, std::uint64_t seed) {
  if (count < 0) throw Error("SampleSurface: count must be >= 0");
  std::vector<double> cumulative_area;
  cumulative_area.reserve(mesh.triangles.size());
  double total = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[t[0]];
    total += 0.5 * (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).norm();
    cumulative_area.push_back(total);
  }
  if (!(total > 0.0)) throw Error("SampleSurface: the mesh has no area");
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  SurfaceSamples samples;
  samples.points.reserve(count);
  samples.normals.reserve(count);
  for (int i = 0; i < count; ++i) {
    const double pick = unit(rng) * total;
    const size_t k = std::min<size_t>(
        std::lower_bound(cumulative_area.begin(), cumulative_area.end(), pick) -
            cumulative_area.begin(),
        mesh.triangles.size() - 1);
    const Eigen::Vector3i& t = mesh.triangles[k];
    const Eigen::Vector3d &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]],
                          &c = mesh.vertices[t[2]];
    // Uniform on the triangle: fold the unit square onto it.
    double u = unit(rng), v = unit(rng);
    if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
    samples.points.push_back(a + u * (b - a) + v * (c - a));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    samples.normals.push_back(n.norm() > 0.0 ? Eigen::Vector3d(n.normalized())
                                             : Eigen::Vector3d::UnitZ());
  }
  return samples;
}

}  // namespace uwscan::scanner
