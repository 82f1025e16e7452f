#include "bench/registration/registration_benchmark.hpp"

#include <functional>

#include "bench/registration/registration_pipelines.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::bench {

void RegistrationBenchOptions::Check() const {
  const OptionChecks check("RegistrationBenchOptions");
  check.AtLeast("threads", threads, 1);
  check.GreaterThan("max_rotation_error_rad", max_rotation_error_rad, 0.0, "rad");
  check.GreaterThan("max_translation_fraction", max_translation_fraction, 0.0);
  pairs.Check();
  for (std::size_t i = 0; i < sweep_voxel_fractions.size(); ++i) {
    const double f = sweep_voxel_fractions[i];
    if (!(f > 0.0 && f < 1.0)) {
      check.Fail("sweep_voxel_fractions[" + std::to_string(i) + "]", "in (0, 1)",
                 OptionValueText(f));
    }
  }
}

namespace {

using Runner = std::function<PipelineRun(const RegistrationPair&, const PipelineParameters&)>;

// Under this share in common, a pair counts with those that have no answer ("none").
constexpr double kMinOverlap = 0.05;

bool WithoutOverlap(bool overlapping, double overlap) {
  return !overlapping || overlap < kMinOverlap;
}

// What a user needs from a pipeline on the pair: the pose accepted and right modulo symmetry; on
// a pair built without overlap, a refusal; on one built to overlap that turned out to share
// almost nothing (a disc's two faces), either a refusal or a pose right modulo symmetry.
bool Useful(const RegistrationPair& pair, bool accepted, bool symmetric_success) {
  if (!pair.overlapping) return !accepted;
  if (pair.overlap < kMinOverlap) return !accepted || symmetric_success;
  return accepted && symmetric_success;
}

// One pipeline over every pair; voxel_fraction > 0 sets the leaf to that fraction of each
// object's size (0: the pair's own, RegistrationPair::voxel_m).
PipelineSummary RunPipeline(const std::string& name, const Runner& run_pipeline,
                            const std::vector<RegistrationPair>& pairs,
                            const RegistrationBenchOptions& o, double voxel_fraction,
                            std::vector<PairOutcome>* outcomes, const Progress& progress) {
  PipelineSummary summary;
  double total_seconds = 0.0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    const RegistrationPair& pair = pairs[i];
    const double voxel_m =
        voxel_fraction > 0.0 ? voxel_fraction * pair.object_size_m : pair.voxel_m;
    const PipelineParameters parameters =
        ParametersFor(pair.object_size_m, o.pairs.seed + i, o.threads, voxel_m);
    const PipelineRun run = run_pipeline(pair, parameters);
    const PoseError error =
        ComparePoses(run.T_target_source, pair.T_target_source_true, pair.source.origin);
    const double limit_m = o.max_translation_fraction * pair.object_size_m;
    PairOutcome outcome;
    outcome.pair = pair.name;
    outcome.pipeline = name;
    outcome.rotation_error_rad = error.rotation_rad;
    outcome.translation_error_m = error.translation_m;
    outcome.symmetric_error_m = SymmetricSurfaceError(
        pair.source, pair.surface, run.T_target_source, pair.T_target_source_true);
    outcome.seconds = run.seconds;
    outcome.success =
        error.rotation_rad < o.max_rotation_error_rad && error.translation_m < limit_m;
    outcome.symmetric_success = outcome.symmetric_error_m < limit_m;
    outcome.accepted = run.accepted;
    outcome.refused_by = run.refused_by;
    outcome.overlapping = pair.overlapping;
    outcome.overlap = pair.overlap;
    outcome.useful = Useful(pair, run.accepted, outcome.symmetric_success);
    if (outcomes) outcomes->push_back(outcome);
    if (progress) progress(name + " pipeline", (i + 1.0) / pairs.size());
    if (WithoutOverlap(pair.overlapping, pair.overlap)) continue;
    ++summary.pairs;
    summary.accepted += outcome.accepted ? 1 : 0;
    summary.successes += outcome.success ? 1 : 0;
    summary.symmetric_successes += outcome.symmetric_success ? 1 : 0;
    total_seconds += run.seconds;
    for (const auto& [stage, seconds] : run.stage_seconds) {
      summary.stage_seconds_per_pair[stage] += seconds;
    }
  }
  if (summary.pairs > 0) {
    summary.success_rate = summary.successes / double(summary.pairs);
    summary.symmetric_success_rate = summary.symmetric_successes / double(summary.pairs);
    summary.seconds_per_pair = total_seconds / summary.pairs;
    for (auto& [stage, seconds] : summary.stage_seconds_per_pair) seconds /= summary.pairs;
  }
  return summary;
}

// Every outcome into its overlap bucket, per pipeline.
std::vector<OverlapBucket> ByOverlap(const std::vector<PairOutcome>& outcomes) {
  std::vector<OverlapBucket> buckets = {{"none", 0.0, 0.0, false, {}},
                                        {"under 30 %", kMinOverlap, 0.3, true, {}},
                                        {"30-50 %", 0.3, 0.5, true, {}},
                                        {"50-70 %", 0.5, 0.7, true, {}},
                                        {"70 % and over", 0.7, 1.01, true, {}}};
  for (const PairOutcome& outcome : outcomes) {
    for (OverlapBucket& bucket : buckets) {
      const bool none = WithoutOverlap(outcome.overlapping, outcome.overlap);
      const bool inside = bucket.overlapping ? !none && outcome.overlap >= bucket.min_overlap &&
                                                   outcome.overlap < bucket.max_overlap
                                             : none;
      if (!inside) continue;
      OverlapBucket::Pipeline& p = bucket.pipelines[outcome.pipeline];
      ++p.pairs;
      p.useful += outcome.useful ? 1 : 0;
      p.wrong_accepted += outcome.accepted && !outcome.useful ? 1 : 0;
      p.seconds_per_pair += outcome.seconds;
    }
  }
  for (OverlapBucket& bucket : buckets) {
    for (auto& [name, p] : bucket.pipelines) {
      p.useful_rate = p.useful / double(p.pairs);
      p.seconds_per_pair /= p.pairs;
    }
  }
  return buckets;
}

}  // namespace

RegistrationBenchResult RunRegistrationBenchmark(const RegistrationBenchOptions& o,
                                                 const Progress& progress) {
  o.Check();
  if (progress) progress("loading and cutting the registration pairs", 0.0);
  const std::vector<RegistrationPair> pairs = MakeRegistrationPairs(o.data_cache, o.pairs);
  if (progress) progress("loading and cutting the registration pairs", 1.0);

  std::vector<std::pair<std::string, Runner>> pipelines = {{"uwscan", RunUwscanPipeline}};
  if (o.run_pcl) pipelines.emplace_back("pcl", RunPclPipeline);
  if (o.run_open3d && Open3dAvailable()) pipelines.emplace_back("open3d", RunOpen3dPipeline);

  RegistrationBenchResult result;
  for (const auto& [name, run_pipeline] : pipelines) {
    result.pipelines[name] =
        RunPipeline(name, run_pipeline, pairs, o, 0.0, &result.outcomes, progress);
  }
  result.buckets = ByOverlap(result.outcomes);
  for (const double fraction : o.sweep_voxel_fractions) {
    const std::string what = "uwscan at voxel " + std::to_string(fraction) + " x size";
    result.voxel_sweep.push_back(
        {fraction, RunPipeline(what, RunUwscanPipeline, pairs, o, fraction, nullptr, progress)});
  }
  return result;
}

}  // namespace uwscan::bench
