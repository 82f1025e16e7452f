#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <string>

#include "bench/registration/registration_pairs.hpp"

namespace uwscan::bench {

// The same stage parameters for every pipeline, scaled to the object: a fair comparison.
struct PipelineParameters {
  double voxel_m = 0.0;            // downsampling leaf
  double normal_radius_m = 0.0;    // neighbourhood of the normals
  double feature_radius_m = 0.0;   // FPFH support
  double inlier_distance_m = 0.0;  // RANSAC inlier threshold
  double icp_distance_m = 0.0;     // ICP correspondence distance
  int ransac_iterations = 0;
  std::uint64_t seed = 1;
  int threads = 1;
};
// voxel_m > 0: that leaf (and the radii and distances scaled to it) instead of size / 50.
PipelineParameters ParametersFor(double object_size_m, std::uint64_t seed, int threads,
                                 double voxel_m = 0.0);

// What one pipeline produced on one pair, and the time each stage took.
struct PipelineRun {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  // Whether the pipeline vouches for its pose. Each by its own rule: uwscan's converged; PCL's
  // RANSAC and ICP both converged (its RANSAC asks for a tenth of the source in agreement); Open3D
  // has no such rule, so its result counts once a tenth of the source lies within the ICP
  // distance (its fitness), as PCL's inlier fraction asks.
  bool accepted = false;
  // uwscan only, when it refused: the stage that did, "coarse" (no hypothesis with enough of the
  // source in agreement) or "icp" (ICP did not converge); empty otherwise.
  std::string refused_by;
  std::map<std::string, double> stage_seconds;  // downsample, normals, features, coarse, icp
  double seconds = 0.0;
};

// uwscan: voxel grid, normals, FPFH, seeded RANSAC with SVD and edge pre-rejection, ICP.
PipelineRun RunUwscanPipeline(const RegistrationPair& pair, const PipelineParameters& p);
// PCL's stock pipeline: VoxelGrid, NormalEstimationOMP, FPFHEstimationOMP,
// SampleConsensusPrerejective, IterativeClosestPoint.
PipelineRun RunPclPipeline(const RegistrationPair& pair, const PipelineParameters& p);
// Open3D's: VoxelDownSample, EstimateNormals, ComputeFPFHFeature, RANSAC on feature matching,
// RegistrationICP. Only when uwscan was built with Open3D (Open3dAvailable()).
bool Open3dAvailable();
PipelineRun RunOpen3dPipeline(const RegistrationPair& pair, const PipelineParameters& p);

}  // namespace uwscan::bench
