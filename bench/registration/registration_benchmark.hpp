#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "bench/progress.hpp"
#include "bench/registration/registration_pairs.hpp"

namespace uwscan::bench {

// uwscan's registration pipeline against PCL's stock one and Open3D's, on the same pairs, with
// the same stage parameters, in one run.
struct RegistrationBenchOptions {
  std::filesystem::path data_cache;  // scripts/fetch_data.sh's folder
  RegistrationPairOptions pairs;
  int threads = 2;
  double max_rotation_error_rad = 2.0 * 3.14159265358979323846 / 180.0;  // success: < 2 deg
  double max_translation_fraction = 0.01;  // success: < 1 % of the object size
  bool run_pcl = true;
  bool run_open3d = true;
  // uwscan's pipeline again at these voxel sizes (fractions of each object's size; the default
  // is 1/50 = 0.02); empty: no sweep.
  std::vector<double> sweep_voxel_fractions;

  void Check() const;
};

struct PairOutcome {
  std::string pair;
  std::string pipeline;
  double rotation_error_rad = 0.0;
  double translation_error_m = 0.0;
  double symmetric_error_m = 0.0;  // ADD-S (SymmetricSurfaceError)
  double seconds = 0.0;
  bool success = false;            // rotation and translation within the thresholds
  bool symmetric_success = false;  // ADD-S within the translation threshold
  bool accepted = false;           // the pipeline vouched for its pose (PipelineRun::accepted)
  std::string refused_by;          // PipelineRun::refused_by
  bool overlapping = true;         // the pair has an answer (RegistrationPair::overlapping)
  double overlap = 0.0;            // RegistrationPair::overlap
  // What a user needs: an overlapping pair's pose accepted and right modulo symmetry; a pair
  // without overlap refused (registration_benchmark.cpp, Useful).
  bool useful = false;
};

// Over the pairs that overlap by 5 % or more (the pose errors mean nothing on the others).
struct PipelineSummary {
  int pairs = 0;
  int accepted = 0;
  int successes = 0;
  double success_rate = 0.0;
  int symmetric_successes = 0;  // judged by ADD-S: a symmetric object's equivalent poses pass
  double symmetric_success_rate = 0.0;
  double seconds_per_pair = 0.0;
  std::map<std::string, double> stage_seconds_per_pair;
};

// uwscan's pipeline at one voxel size of the sweep.
struct VoxelSweepRow {
  double voxel_fraction = 0.0;  // of each object's size
  PipelineSummary summary;
};

// The pairs whose overlap lies in [min_overlap, max_overlap), or those without any.
struct OverlapBucket {
  // "none" (built without overlap, or under 5 % in common), "under 30 %", "30-50 %", "50-70 %",
  // "70 % and over"
  std::string name;
  double min_overlap = 0.0, max_overlap = 0.0;
  bool overlapping = true;
  struct Pipeline {
    int pairs = 0;
    int useful = 0;  // PairOutcome::useful
    double useful_rate = 0.0;
    // Poses accepted that are wrong (modulo symmetry), or accepted where there is no answer:
    // what a user would act on unwarned.
    int wrong_accepted = 0;
    double seconds_per_pair = 0.0;
  };
  std::map<std::string, Pipeline> pipelines;
};

struct RegistrationBenchResult {
  std::map<std::string, PipelineSummary> pipelines;  // "uwscan", "pcl", "open3d"
  std::vector<OverlapBucket> buckets;                // every pair once, by its overlap
  std::vector<PairOutcome> outcomes;
  std::vector<VoxelSweepRow> voxel_sweep;
};

RegistrationBenchResult RunRegistrationBenchmark(const RegistrationBenchOptions& options,
                                                 const Progress& progress = {});

}  // namespace uwscan::bench
