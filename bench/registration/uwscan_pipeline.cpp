// uwscan's registration pipeline as the benchmark runs it, and the parameters every pipeline
// shares (those of perception::RegistrationPipelineOptions::ForObjectSize).
#include "bench/registration/registration_pipelines.hpp"
#include "perception/registration/registration_pipeline.hpp"

namespace uwscan::bench {

PipelineParameters ParametersFor(double object_size_m, std::uint64_t seed, int threads,
                                 double voxel_m) {
  const perception::RegistrationPipelineOptions o =
      perception::RegistrationPipelineOptions::ForObjectSize(object_size_m, seed, threads, voxel_m);
  PipelineParameters p;
  p.voxel_m = o.voxel_m;
  p.normal_radius_m = o.normal_radius_m;
  p.feature_radius_m = o.feature_radius_m;
  p.inlier_distance_m = o.coarse.inlier_distance_m;
  p.icp_distance_m = o.icp.max_correspondence_distance_m.front();
  p.ransac_iterations = o.coarse.max_iterations;
  p.seed = seed;
  p.threads = threads;
  return p;
}

PipelineRun RunUwscanPipeline(const RegistrationPair& pair, const PipelineParameters& p) {
  perception::RegistrationPipelineOptions o =
      perception::RegistrationPipelineOptions::ForObjectSize(pair.object_size_m, p.seed, p.threads,
                                                             p.voxel_m);
  o.source_viewpoint = pair.source_viewpoint;
  o.target_viewpoint = pair.target_viewpoint;
  const perception::RegistrationPipelineResult result =
      perception::RegisterClouds(pair.source, pair.target, o);
  PipelineRun run;
  run.T_target_source = result.fine.T_target_source;
  run.accepted = result.fine.converged;
  if (!run.accepted) run.refused_by = result.coarse.converged ? "icp" : "coarse";
  run.stage_seconds = result.stage_seconds;
  for (const auto& [stage, seconds] : result.stage_seconds) run.seconds += seconds;
  return run;
}

}  // namespace uwscan::bench
