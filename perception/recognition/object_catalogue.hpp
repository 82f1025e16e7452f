#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "perception/recognition/object_database.hpp"
#include "scanner/common/triangle_mesh.hpp"

namespace uwscan::perception {

// An object to put in a database: its mesh (object frame), grasp frames and, when declared,
// its symmetries (otherwise found from the mesh).
struct ObjectSource {
  std::string id;
  std::string source;  // "procedural: valve_wheel" or the mesh file
  scanner::TriangleMesh mesh;
  std::vector<GraspFrame> grasps;
  std::optional<std::vector<SymmetryAxis>> symmetries;
};

// The procedural IMR objects uwscan generates itself, with sensible grasp frames: pipe (its
// body), elbow (mid-bend), tee (the run, clear of the branch), flange (its rim), valve_wheel
// and valve_lever (the handle), panel (an intervention panel: a handle), and their symmetries
// declared by construction. Names in
// CatalogueNames().
std::vector<std::string> CatalogueNames();
// Throws uwscan::Error listing the known names when `name` is not one.
ObjectSource CatalogueObject(const std::string& name);

// A mesh file (PLY/OFF/STL/OBJ, metres) with, when it exists, a sidecar MESH.grasps.yaml:
//   uwscan_format: 1
//   id: valve_dn100              # optional, default: the file's stem
//   grasps:                      # optional
//     - {name: handle, pose: {translation_m: [x, y, z], rotation_xyzw: [qx, qy, qz, qw]}}
//   symmetries:                  # optional: declared, replacing detection from the mesh
//     - {point_m: [0, 0, 0], axis: [0, 0, 1], order: 0}   # 0 continuous, N >= 2 N-fold
// The mesh's coordinates are multiplied by units_to_m (> 0: 0.001 for a mesh in millimetres);
// the sidecar is in metres. An object that comes out over kLargestObject_m or under
// kSmallestObject_m across is refused with a hint about units: no IMR object is that size, a mesh
// in other units is.
// Throws uwscan::Error naming the file (and line) on anything missing or malformed.
inline constexpr double kLargestObject_m = 10.0;
inline constexpr double kSmallestObject_m = 0.005;
ObjectSource MeshObject(const std::filesystem::path& mesh_path, double units_to_m = 1.0);

// An object taught from a scan of it: a point cloud (.pcd, .xyz, or a .ply without faces) in
// units_to_m, whose surface is its points as small discs facing out (CloudSurface), with the
// sidecar, the id and the size check of MeshObject. Throws uwscan::Error naming the file when it
// cannot be read, holds too few points for a surface, or is a size no object is.
ObjectSource CloudObject(const std::filesystem::path& cloud_path, double units_to_m = 1.0);

// Whether a file holds a point cloud rather than a mesh: .pcd or .xyz, or a PLY without faces
// (no face element, or "element face 0" as MeshLab writes clouds).
bool IsCloudFile(const std::filesystem::path& path);

// The sidecar's path for a mesh: the mesh path with its extension replaced by ".grasps.yaml".
std::filesystem::path GraspSidecarPath(const std::filesystem::path& mesh_path);

}  // namespace uwscan::perception
