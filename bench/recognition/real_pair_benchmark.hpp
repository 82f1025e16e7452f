#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace uwscan::bench {

// Recognition on data no one here made: PCL's correspondence grouping tutorial pair, a milk
// carton's model (milk.pcd, a cloud) and a real Kinect scene holding it among other things
// (milk_cartoon_all_small_clorox.pcd), fetched by scripts/fetch_data.sh. uwscan teaches the
// model as build-db teaches a cloud and recognises the scene as `recognize` reads it; the
// reference is PCL's correspondence grouping with the tutorial's parameters (uniform sampling,
// SHOT descriptors, geometric consistency), its best instance refined by PCL's ICP, in the same
// run. Poses map the model file's coordinates to the scene file's.
struct RealPairOptions {
  std::filesystem::path data_cache;   // scripts/fetch_data.sh's folder
  std::filesystem::path table_cache;  // the virtual scanner's cone table
  int threads = 2;                    // >= 1
  std::uint64_t seed = 1;
  void Check() const;
};

struct RealPairPose {
  std::optional<Eigen::Isometry3d> T_scene_model;  // none: the object was not found
  double seconds = 0.0;  // uwscan: recognition (teaching apart); PCL: its whole pipeline
};

struct RealPairFigures {
  std::string model, scene;
  RealPairPose uwscan, pcl;
  double database_seconds = 0.0;  // uwscan's teaching, apart
  // Between the two poses, when both found the object: the rotation between them and how far
  // apart they put the model's centroid.
  std::optional<double> rotation_difference_rad, translation_difference_m;
};

// Throws uwscan::Error naming a missing file when the data cache lacks the pair.
RealPairFigures RunRealPairBench(const RealPairOptions& options);

}  // namespace uwscan::bench
