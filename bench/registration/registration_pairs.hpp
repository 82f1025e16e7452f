#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "perception/cloud/point_cloud.hpp"

namespace uwscan::bench {

// A registration problem with its answer: align `source` onto `target`.
struct RegistrationPair {
  std::string name;
  perception::PointCloud source;
  perception::PointCloud target;
  Eigen::Isometry3d T_target_source_true = Eigen::Isometry3d::Identity();
  Eigen::Vector3d source_viewpoint = Eigen::Vector3d::Zero();  // sensor, in the source's frame
  Eigen::Vector3d target_viewpoint = Eigen::Vector3d::Zero();  // sensor, in the target's frame
  double object_size_m = 0.0;  // bounding-box diagonal of the target, for the success test
  // The downsampling leaf every pipeline gets: 0 for an object (its size / 50); for a scan, what
  // `uwscan register` picks for two clouds (RegistrationPipelineOptions::ForClouds).
  double voxel_m = 0.0;
  // The whole object's surface in the source's frame (a mesh's full sampling; a scan's every
  // point): what a symmetry-aware error measures against, since a pose equivalent by symmetry
  // may move the seen side onto a side the source view never saw.
  perception::PointCloud surface;
  // Whether the pair was built to share surface: two unrelated objects, or two parts of a scan
  // with a gap between them, have no answer, and a pipeline succeeds on them by refusing.
  bool overlapping = true;
  // For a pair built to overlap, the share of the smaller side that the other covers once truly
  // placed (MeasureOverlap); it can still come out near 0 (views of a disc's two faces).
  double overlap = 0.0;
  // The source's last points are this many outliers (no surface), left out of the overlap.
  std::size_t source_outliers = 0;
};

struct RegistrationPairOptions {
  int mesh_samples = 40000;          // surface samples per mesh before the views are cut
  double mesh_size_m = 0.5;          // meshes are scaled to this bounding-box diagonal
  double noise_sigma_m = 0.0005;     // Gaussian noise added to every view
  double view_separation_rad = 0.6;  // angle between the two viewpoints of a mesh pair
  int pairs_per_mesh = 2;
  std::uint64_t seed = 1;
  bool real_scans = true;  // add pairs built from bun0.pcd and table_scene_lms400.pcd
  // Add the pairs users find hard: views further apart, one of them sparser or with outliers;
  // the real scans cut into two overlapping parts; and pairs that do not overlap at all (two
  // unrelated objects, a scan's two ends); and per mesh two sweeps of the virtual scanner 0.5-1.4
  // rad apart at 0.7-1.3 m (the scanner's own density and noise), each in its camera's frame.
  bool hard_pairs = true;
  double outlier_fraction = 0.05;     // of a hard pair's source points added as outliers, [0, 1)
  std::filesystem::path table_cache;  // folder keeping the sweeps' cone table (optional)

  void Check() const;
};

// Pairs from the cached real data (scripts/fetch_data.sh): CGAL meshes sampled into two
// partial views each (independent surface samplings, back faces culled, different
// viewpoints, so the overlap is partial), and the real scans against randomly resampled,
// noisy copies of themselves (full overlap: these test real noise and density, not overlap);
// with hard_pairs, the harder pairs after them.
// Every source is moved by a random rigid motion (any rotation, translation up to the object size;
// a sweep's source, in its camera's frame, turns about the camera, a metre from the object).
// Each pair's overlap is measured within 1 % of its object's size, or 2.5 sampling steps of the
// sparser cloud if more. Throws uwscan::Error naming the missing file when the cache is incomplete.
std::vector<RegistrationPair> MakeRegistrationPairs(const std::filesystem::path& data_cache,
                                                    const RegistrationPairOptions& options);

// The smaller of the two shares: of the source's points (its outliers left out) that lie within
// `radius_m` of a target point once moved by the true pose, and of the target's that lie within
// it of a moved source point.
double MeasureOverlap(const RegistrationPair& pair, double radius_m);

// Rotation error (rad) of an estimate against the truth, and its translation error (m) where
// it matters: the displacement it gives `at_point` (the source's centre) against the truth's.
struct PoseError {
  double rotation_rad;
  double translation_m;
};
PoseError ComparePoses(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth,
                       const Eigen::Vector3d& at_point);

// ADD-S, the error of a pose that a symmetric object cannot show wrong: the mean distance from
// each source point moved by `estimate` to the nearest point of the object's whole `surface`
// (source frame) moved by `truth` (at most `max_points` source points, evenly spaced, are
// measured). A pose that differs from the truth by a symmetry of the surface scores (near)
// zero, where the rotation error does not.
double SymmetricSurfaceError(const perception::PointCloud& source,
                             const perception::PointCloud& surface,
                             const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth,
                             std::size_t max_points = 2000);

}  // namespace uwscan::bench
