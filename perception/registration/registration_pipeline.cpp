#include "perception/registration/registration_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <numeric>

#include "perception/cloud/cloud_scale.hpp"
#include "perception/features/fpfh.hpp"
#include "perception/preprocessing/normals.hpp"
#include "perception/preprocessing/voxel_filter.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::perception {
namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct Prepared {
  CloudWithNormals cloud;
  FpfhFeatures features;
};

// At least 3 points must keep a surface normal at the voxel, or no stage has anything to pair:
// say why in terms of the cloud, not of the stage that would fail on it.
void RequireSurface(const PointCloud& cloud, std::size_t voxels, const CloudWithNormals& prepared,
                    const char* name, double voxel_m) {
  if (prepared.cloud.size() >= 3) return;
  throw Error(std::string(name) + ": " + std::to_string(prepared.cloud.size()) + " of its " +
              std::to_string(voxels) + " voxels of " + std::to_string(voxel_m) + " m (from " +
              std::to_string(cloud.size()) +
              " points) have a surface normal, at least 3 are needed: the cloud is collinear or "
              "too sparse at this voxel (--voxel), or its coordinates are so large that the file's "
              "32-bit floats rounded them to a coarse grid");
}

Prepared Prepare(const PointCloud& cloud, const char* name, const Eigen::Vector3d& viewpoint,
                 const RegistrationPipelineOptions& o, bool features,
                 std::map<std::string, double>* seconds) {
  Clock::time_point start = Clock::now();
  VoxelFilterOptions voxel;
  voxel.leaf_m = o.voxel_m;
  const PointCloud down = VoxelDownsample(cloud, voxel);
  (*seconds)["downsample"] += Since(start);

  start = Clock::now();
  NormalOptions normal_options;
  normal_options.radius_m = o.normal_radius_m;
  normal_options.viewpoint = viewpoint;
  normal_options.threads = o.threads;
  Prepared out;
  out.cloud = AttachNormals(down, EstimateNormals(down, normal_options));
  (*seconds)["normals"] += Since(start);
  RequireSurface(cloud, down.size(), out.cloud, name, o.voxel_m);
  if (!features) return out;

  start = Clock::now();
  std::vector<std::size_t> all(out.cloud.cloud.size());
  std::iota(all.begin(), all.end(), std::size_t{0});
  FpfhOptions fpfh;
  fpfh.radius_m = o.feature_radius_m;
  fpfh.threads = o.threads;
  out.features = ComputeFpfh(out.cloud.cloud, all, fpfh);
  (*seconds)["features"] += Since(start);
  return out;
}

}  // namespace

RegistrationPipelineOptions RegistrationPipelineOptions::ForObjectSize(double size_m,
                                                                       std::uint64_t seed,
                                                                       int threads,
                                                                       double voxel_m) {
  if (!(size_m > 0.0) || !std::isfinite(size_m)) {
    throw Error("registration: object size must be finite and > 0 (got " + std::to_string(size_m) +
                " m)");
  }
  if (!(voxel_m >= 0.0) || !std::isfinite(voxel_m)) {
    throw Error("registration: voxel must be finite and >= 0 (0: size / 50; got " +
                std::to_string(voxel_m) + " m)");
  }
  RegistrationPipelineOptions o;
  o.voxel_m = voxel_m > 0.0 ? voxel_m : size_m / 50.0;
  o.normal_radius_m = 2.5 * o.voxel_m;
  o.feature_radius_m = 5.0 * o.voxel_m;
  o.coarse.inlier_distance_m = 1.5 * o.voxel_m;
  o.coarse.max_iterations = 50000;
  o.coarse.seed = seed;
  o.coarse.threads = threads;
  o.coarse.min_inlier_fraction = 0.01;
  o.icp.method = IcpMethod::kPointToPlane;
  o.icp.max_correspondence_distance_m = {1.5 * o.voxel_m, 0.75 * o.voxel_m};
  // Converged means the pose stopped changing at the scale of the data: a step below 1 % of a
  // voxel at the object's edge. With noisy partial views ICP otherwise ends its iterations
  // oscillating by micrometres around the answer, short of tolerances of 1e-6, and says it
  // did not converge although the pose is as good as the data allows.
  o.icp.translation_tolerance_m = 0.01 * o.voxel_m;
  o.icp.rotation_tolerance_rad = o.icp.translation_tolerance_m / (0.5 * size_m);
  o.icp.relative_rmse_tolerance = 1e-4;
  // A pipe or a cylinder rolls about and slides along its axis by the noise at every step: the
  // step is measured where the pairs pin the pose, directions with at least 1 % of the largest
  // information (a standard deviation within 10x of the best-determined direction's).
  o.icp.weak_direction_ratio = 0.01;
  o.icp.threads = threads;
  o.threads = threads;
  return o;
}

RegistrationPipelineOptions RegistrationPipelineOptions::ForClouds(const PointCloud& source,
                                                                   const PointCloud& target,
                                                                   std::uint64_t seed,
                                                                   int threads) {
  RequireValidCloud(source, "registration source");
  RequireValidCloud(target, "registration target");
  const double size_m = BoundingBoxDiagonal(target);
  if (!(size_m > 0.0)) throw Error("registration: the target cloud has no extent (give a voxel)");
  const double scale_voxel_m = std::min(RobustDiagonal(target) / 100.0, size_m / 50.0);
  const double spacing_m = std::max(MedianPointSpacing(source), MedianPointSpacing(target));
  const double voxel_m = std::max(scale_voxel_m, 2.0 * spacing_m);
  return ForObjectSize(size_m, seed, threads, voxel_m > 0.0 ? voxel_m : size_m / 50.0);
}

void RegistrationPipelineOptions::Check() const {
  const OptionChecks check("RegistrationPipelineOptions");
  check.Positive("voxel_m", voxel_m, "m");
  check.Positive("normal_radius_m", normal_radius_m, "m");
  check.Positive("feature_radius_m", feature_radius_m, "m");
  check.Require(source_viewpoint.allFinite(), "source_viewpoint", "finite coordinates");
  check.Require(target_viewpoint.allFinite(), "target_viewpoint", "finite coordinates");
  check.AtLeast("threads", threads, 0);
  coarse.Check();
  icp.Check();
}

RegistrationPipelineResult RegisterClouds(
    const PointCloud& source, const PointCloud& target, const RegistrationPipelineOptions& options,
    const std::optional<Eigen::Isometry3d>& T_target_source_init) {
  RegistrationPipelineOptions o = options;
  o.coarse.threads = o.threads;
  o.icp.threads = o.threads;
  o.Check();
  RequireValidCloud(source, "registration source", 3);
  RequireValidCloud(target, "registration target", 3);
  RegistrationPipelineResult result;
  const bool coarse_needed = !T_target_source_init.has_value();
  const Prepared s = Prepare(source, "registration source", o.source_viewpoint, o, coarse_needed,
                             &result.stage_seconds);
  const Prepared t = Prepare(target, "registration target", o.target_viewpoint, o, coarse_needed,
                             &result.stage_seconds);

  Eigen::Isometry3d start_pose = T_target_source_init.value_or(Eigen::Isometry3d::Identity());
  if (coarse_needed) {
    const Clock::time_point start = Clock::now();
    result.coarse = AlignCoarse(s.cloud.cloud, s.features, t.cloud.cloud, t.features, o.coarse);
    result.stage_seconds["coarse"] += Since(start);
    if (!result.coarse.converged) {
      result.fine = result.coarse;  // no convincing start: ICP would only polish a guess
      return result;
    }
    start_pose = result.coarse.T_target_source;
  }
  const Clock::time_point start = Clock::now();
  result.fine = AlignIcp(s.cloud.cloud, t.cloud.cloud, start_pose, o.icp);
  result.stage_seconds["icp"] += Since(start);
  return result;
}

}  // namespace uwscan::perception
