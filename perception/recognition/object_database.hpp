#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <vector>

#include "perception/cloud/point_cloud.hpp"
#include "perception/features/esf.hpp"
#include "perception/features/fpfh.hpp"
#include "perception/recognition/object_symmetry.hpp"

namespace uwscan::perception {

// A frame on an object where a gripper takes it: origin at the grasp point, z the approach
// direction (from the gripper towards the object), x the closing direction of the fingers.
struct GraspFrame {
  std::string name;
  Eigen::Isometry3d T_O_G = Eigen::Isometry3d::Identity();
};

// One partial view of an object by the virtual scanner.
struct ObjectView {
  Eigen::Isometry3d T_O_C = Eigen::Isometry3d::Identity();  // the camera in the object frame
  EsfDescriptor esf = EsfDescriptor::Zero();                // of the view's voxelised points
  int points = 0;                                           // voxelised points of the view
  // The view's voxelised points in its camera frame: what the pose's coarse stage matches a
  // segment against (a partial scan like the segment, unlike the whole model, whose thin walls
  // and inner bores give FPFH neighbourhoods no scan sees).
  PointCloud cloud;
};

// What recognition needs of one object: the model surface with normals and FPFH for its pose,
// its size, its symmetries and grasp frames, and the ESF of each view for its identity.
struct ObjectModel {
  std::string id;
  std::string source;       // mesh file or procedural shape it was built from
  double diameter_m = 0.0;  // largest distance between two model points
  PointCloud model;         // surface samples with outward normals, object frame, voxelised
  FpfhFeatures features;    // at every model point
  std::vector<SymmetryAxis> symmetries;
  bool symmetries_declared = false;  // declared beside the mesh, not found from it
  std::vector<GraspFrame> grasps;
  std::vector<ObjectView> views;
};

// The parameters the database was built with, which recognition must use the same way.
struct ObjectDatabaseParameters {
  double voxel_m = 0.005;           // leaf of every view, model and scan cloud
  double normal_radius_m = 0.0125;  // normals of models and scans
  double feature_radius_m = 0.025;  // FPFH support
  std::string scanner;              // the scanner the views were made with, for messages
};

struct ObjectDatabase {
  ObjectDatabaseParameters parameters;
  std::vector<ObjectModel> objects;

  // Writes one file atomically (a temporary beside it, then a rename): "UWSCANOBJ", u32 format
  // version, the parameters, the objects, then a 64-bit FNV-1a checksum of everything before
  // it. Throws uwscan::Error naming the file.
  void Save(const std::filesystem::path& path) const;
  // Throws uwscan::Error in one line naming the file and the problem: missing, not an object
  // database (foreign file), a newer or older format version, truncated, corrupt (checksum or
  // a value out of range).
  static ObjectDatabase Load(const std::filesystem::path& path);

  // The largest diameter of its objects, metres (0 when it has none).
  double LargestDiameter() const;
};

inline constexpr std::uint32_t kObjectDatabaseVersion = 1;

}  // namespace uwscan::perception
