#include "bench/registration/features_benchmark.hpp"

#include <chrono>
#include <numeric>

#include "bench/registration/registration_pipelines.hpp"
#include "perception/features/esf.hpp"
#include "perception/features/fpfh.hpp"
#include "perception/preprocessing/normals.hpp"
#include "perception/preprocessing/voxel_filter.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::bench {
namespace {

using Clock = std::chrono::steady_clock;

template <typename F>
double Time(F&& f) {
  const Clock::time_point start = Clock::now();
  f();
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

FeaturesBenchResult RunFeaturesBenchmark(const FeaturesBenchOptions& o, const Progress& progress) {
  RegistrationPairOptions pair_options = o.pairs;
  pair_options.real_scans = false;  // object views: what recognition describes
  pair_options.hard_pairs = false;
  const std::vector<RegistrationPair> pairs = MakeRegistrationPairs(o.data_cache, pair_options);
  FeaturesBenchResult r;
  int esf_pairs = 0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    const perception::PointCloud& view = pairs[i].target;
    const PipelineParameters p = ParametersFor(pairs[i].object_size_m, 1, o.threads);
    perception::VoxelFilterOptions voxel;
    voxel.leaf_m = p.voxel_m;
    const perception::PointCloud down = perception::VoxelDownsample(view, voxel);
    perception::NormalOptions normal_options;
    normal_options.radius_m = p.normal_radius_m;
    normal_options.threads = o.threads;
    const perception::CloudWithNormals with_normals =
        perception::AttachNormals(down, perception::EstimateNormals(down, normal_options));
    std::vector<std::size_t> all(with_normals.cloud.size());
    std::iota(all.begin(), all.end(), std::size_t{0});
    perception::FpfhOptions fpfh;
    fpfh.radius_m = p.feature_radius_m;
    fpfh.threads = o.threads;
    r.fpfh_uwscan_s += Time([&] { perception::ComputeFpfh(with_normals.cloud, all, fpfh); });
    r.fpfh_pcl_s += Time([&] { perception::ComputeFpfhPcl(with_normals.cloud, all, fpfh); });

    perception::EsfResult ours, pcl;
    r.esf_uwscan_s += Time([&] { ours = perception::ComputeEsf(view); });
    r.esf_pcl_s += Time([&] { pcl = perception::ComputePclEsf(view); });
    perception::EsfOptions other_seed;
    other_seed.seed = 2;
    const perception::EsfResult resampled = perception::ComputeEsf(view, other_seed);
    if (ours.ok && pcl.ok && resampled.ok) {
      r.esf_chi2_to_pcl +=
          perception::ChiSquareDistance(ours.histogram.data(), pcl.histogram.data(), 640);
      r.esf_chi2_seed_to_seed +=
          perception::ChiSquareDistance(ours.histogram.data(), resampled.histogram.data(), 640);
      ++esf_pairs;
    }
    ++r.clouds;
    if (progress) progress("features", (i + 1.0) / pairs.size());
  }
  if (r.clouds == 0) throw Error("bench features: no clouds");
  r.fpfh_uwscan_s /= r.clouds, r.fpfh_pcl_s /= r.clouds;
  r.esf_uwscan_s /= r.clouds, r.esf_pcl_s /= r.clouds;
  if (esf_pairs > 0) r.esf_chi2_to_pcl /= esf_pairs, r.esf_chi2_seed_to_seed /= esf_pairs;
  return r;
}

}  // namespace uwscan::bench
