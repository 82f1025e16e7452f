#include "bench/registration_benchmark.hpp"

#include <functional>

#include "bench/registration_pipelines.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::bench {

void RegistrationBenchOptions::Check() const {
  if (threads < 1) throw Error("bench registration: threads must be >= 1");
  if (!(max_rotation_error_rad > 0.0) || !(max_translation_fraction > 0.0)) {
    throw Error("bench registration: success thresholds must be > 0");
  }
  pairs.Check();
}

RegistrationBenchResult RunRegistrationBenchmark(const RegistrationBenchOptions& o,
                                                 const Progress& progress) {
  o.Check();
  if (progress) progress("loading and cutting the registration pairs", 0.0);
  const std::vector<RegistrationPair> pairs = MakeRegistrationPairs(o.data_cache, o.pairs);
  if (progress) progress("loading and cutting the registration pairs", 1.0);

  using Runner = std::function<PipelineRun(const RegistrationPair&, const PipelineParameters&)>;
  std::vector<std::pair<std::string, Runner>> pipelines = {{"uwscan", RunUwscanPipeline}};
  if (o.run_pcl) pipelines.emplace_back("pcl", RunPclPipeline);
  if (o.run_open3d && Open3dAvailable()) pipelines.emplace_back("open3d", RunOpen3dPipeline);

  RegistrationBenchResult result;
  for (const auto& [name, run_pipeline] : pipelines) {
    PipelineSummary& summary = result.pipelines[name];
    double total_seconds = 0.0;
    for (size_t i = 0; i < pairs.size(); ++i) {
      const RegistrationPair& pair = pairs[i];
      const PipelineParameters parameters =
          ParametersFor(pair.object_size_m, o.pairs.seed + i, o.threads);
      const PipelineRun run = run_pipeline(pair, parameters);
      const PoseError error =
          ComparePoses(run.T_target_source, pair.T_target_source_true, pair.source.origin);
      PairOutcome outcome{pair.name, name, error.rotation_rad, error.translation_m, run.seconds,
                          error.rotation_rad < o.max_rotation_error_rad &&
                              error.translation_m < o.max_translation_fraction * pair.object_size_m};
      summary.successes += outcome.success ? 1 : 0;
      total_seconds += run.seconds;
      for (const auto& [stage, seconds] : run.stage_seconds) {
        summary.stage_seconds_per_pair[stage] += seconds / pairs.size();
      }
      result.outcomes.push_back(outcome);
      if (progress) progress(name + " pipeline", (i + 1.0) / pairs.size());
    }
    summary.pairs = static_cast<int>(pairs.size());
    summary.success_rate = pairs.empty() ? 0.0 : summary.successes / double(pairs.size());
    summary.seconds_per_pair = pairs.empty() ? 0.0 : total_seconds / pairs.size();
  }
  return result;
}

}  // namespace uwscan::bench
