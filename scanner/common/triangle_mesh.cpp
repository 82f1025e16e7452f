#include "scanner/common/triangle_mesh.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <random>
#include <string>
#include <system_error>

#include "scanner/common/atomic_file.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"
#include "scanner/common/off_reader.hpp"
#include "scanner/common/ply_reader.hpp"
#include "scanner/common/random_draws.hpp"
#include "scanner/common/stl_reader.hpp"

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

namespace {

// PLY, OFF and STL through uwscan's bounded readers: Assimp 5.2's importers crash or hang on
// damaged PLY and OFF files (`uwscan bench robustness`) and leak on damaged STL files
// (tests/fuzz/regressions/mesh_stl); OBJ goes through Assimp.
TriangleMesh LoadPlyMesh(const std::filesystem::path& path) {
  PlyContent ply = ReadPly(path, /*faces=*/true);
  TriangleMesh mesh;
  mesh.vertices = std::move(ply.vertices);
  mesh.triangles = std::move(ply.triangles);
  return mesh;
}

std::string LowerExtension(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

// The format a file name says, for messages: "OBJ", "PCD", ...
std::string FormatName(const std::string& lower_extension) {
  std::string name =
      lower_extension.empty() ? std::string("no extension") : lower_extension.substr(1);
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return name;
}

// Point-cloud formats: what a user who scanned an object holds, not a mesh.
bool IsPointCloudExtension(const std::string& lower_extension) {
  for (const char* cloud : {".pcd", ".xyz", ".pts", ".las", ".laz", ".e57"}) {
    if (lower_extension == cloud) return true;
  }
  return false;
}

// Whether a mesh format is read by that extension: PLY, OFF and STL by uwscan's readers, the
// others (OBJ among them) by Assimp if it knows the extension. A file with any other extension is
// refused before Assimp, which would guess a format from its contents and name the file by an
// extension that says nothing.
bool IsMeshExtension(const std::string& lower_extension) {
  if (lower_extension == ".ply" || lower_extension == ".off" || lower_extension == ".stl")
    return true;
  return !lower_extension.empty() && Assimp::Importer().IsExtensionSupported(lower_extension);
}

TriangleMesh LoadAssimpMesh(const std::filesystem::path& path) {
  Assimp::Importer importer;
  const aiScene* scene =
      importer.ReadFile(path.string(), aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                           aiProcess_DropNormals | aiProcess_FindDegenerates);
  if (scene == nullptr) {
    throw Error(path.string() + ": cannot read a mesh in " + FormatName(LowerExtension(path)) +
                " format (through Assimp): " + importer.GetErrorString());
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
  return mesh;
}

}  // namespace

TriangleMesh LoadMesh(const std::filesystem::path& path) {
  RequireRegularFile(path, path.string());
  const std::string extension = LowerExtension(path);
  if (IsPointCloudExtension(extension)) {
    const bool read_here = extension == ".pcd" || extension == ".xyz";
    throw Error(path.string() + ": " + FormatName(extension) +
                (read_here ? " holds a point cloud, not a mesh: give a mesh with faces (PLY, OFF, "
                             "STL or OBJ)"
                           : " holds a point cloud, in a format uwscan does not read: convert it "
                             "to PLY, PCD or XYZ"));
  }
  if (!IsMeshExtension(extension)) {
    throw Error(path.string() + ": " +
                (extension.empty() ? std::string("no extension") : "extension " + extension) +
                " names no mesh format read here (PLY, OFF, STL, OBJ, or another Assimp reads by "
                "its extension: DAE, FBX, 3DS, GLTF and more)");
  }
  const TriangleMesh mesh = extension == ".ply"   ? LoadPlyMesh(path)
                            : extension == ".off" ? ReadOff(path)
                            : extension == ".stl" ? ReadStl(path)
                                                  : LoadAssimpMesh(path);
  if (mesh.vertices.empty()) {
    throw Error(path.string() + ": " + FormatName(extension) +
                " with no vertex: not a mesh in that format, or an empty one");
  }
  if (mesh.triangles.empty()) {
    throw Error(path.string() + ": " + FormatName(extension) + " with " +
                std::to_string(mesh.vertices.size()) +
                " vertices and no triangle: a point cloud, not a mesh (give a mesh with faces)");
  }
  for (const Eigen::Vector3d& v : mesh.vertices) {
    if (!v.allFinite()) throw Error(path.string() + ": the mesh has a non-finite vertex");
  }
  return mesh;
}

namespace {

// Appends the little-endian bytes of a 4-byte value (PLY binary_little_endian).
template <typename T>
void PutLittleEndian(std::string* out, T value) {
  static_assert(sizeof(T) == 4);
  std::uint32_t bits = 0;
  std::memcpy(&bits, &value, 4);
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((bits >> (8 * i)) & 0xffu));
}

}  // namespace

void WriteMeshPly(const TriangleMesh& mesh, const std::filesystem::path& path) {
  const std::string name = path.string();
  if (mesh.triangles.empty()) throw Error(name + ": cannot write a mesh without triangles");
  const int count = static_cast<int>(mesh.vertices.size());
  for (const Eigen::Vector3d& v : mesh.vertices) {
    if (!v.allFinite()) throw Error(name + ": cannot write a mesh with a non-finite vertex");
  }
  for (const Eigen::Vector3i& t : mesh.triangles) {
    if ((t.array() < 0).any() || (t.array() >= count).any()) {
      throw Error(name + ": cannot write a mesh whose triangle indexes a missing vertex");
    }
  }
  std::string data = "ply\nformat binary_little_endian 1.0\ncomment written by uwscan\n";
  data += "element vertex " + std::to_string(count) + "\n";
  data += "property float x\nproperty float y\nproperty float z\n";
  data += "element face " + std::to_string(mesh.triangles.size()) + "\n";
  data += "property list uchar int vertex_indices\nend_header\n";
  data.reserve(data.size() + 12 * mesh.vertices.size() + 13 * mesh.triangles.size());
  for (const Eigen::Vector3d& v : mesh.vertices) {
    for (int i = 0; i < 3; ++i) PutLittleEndian(&data, static_cast<float>(v[i]));
  }
  for (const Eigen::Vector3i& t : mesh.triangles) {
    data.push_back(3);
    for (int i = 0; i < 3; ++i) PutLittleEndian(&data, static_cast<std::int32_t>(t[i]));
  }
  WriteFileAtomically(path, data);
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
    const size_t k =
        std::min<size_t>(std::lower_bound(cumulative_area.begin(), cumulative_area.end(), pick) -
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

std::vector<Eigen::Vector3d> ScannedSurface(const TriangleMesh& mesh, int count, double sigma_m,
                                            std::uint64_t seed) {
  if (!(sigma_m >= 0.0) || !std::isfinite(sigma_m))
    throw Error("ScannedSurface: sigma_m must be finite and >= 0");
  std::vector<Eigen::Vector3d> points = SampleSurface(mesh, count, seed).points;
  if (sigma_m == 0.0) return points;
  std::mt19937_64 rng(seed + 1);
  std::normal_distribution<double> noise(0.0, sigma_m);
  for (Eigen::Vector3d& p : points) p += DrawVector3(noise, rng);
  return points;
}

}  // namespace uwscan::scanner
