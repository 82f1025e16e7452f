#pragma once

#include <filesystem>

#include "bench/progress.hpp"
#include "bench/registration/registration_pairs.hpp"

namespace uwscan::bench {

// FPFH and ESF, uwscan's against PCL's, on the registration benchmark's object views: time per
// cloud, and how close uwscan's ESF comes to PCL's (chi-square distance), beside how far two
// samplings of the same view (uwscan's ESF with two seeds) land apart: the noise floor. (PCL's
// own reruns cannot serve: it seeds rand() from the clock in seconds, so two calls within a
// second give the same histogram.)
struct FeaturesBenchOptions {
  std::filesystem::path data_cache;
  RegistrationPairOptions pairs;
  int threads = 2;
};

struct FeaturesBenchResult {
  int clouds = 0;
  double fpfh_uwscan_s = 0.0;  // per cloud
  double fpfh_pcl_s = 0.0;
  double esf_uwscan_s = 0.0;
  double esf_pcl_s = 0.0;
  double esf_chi2_to_pcl = 0.0;        // mean chi-square(uwscan, PCL)
  double esf_chi2_seed_to_seed = 0.0;  // mean chi-square(uwscan seed 1, uwscan seed 2)
};

FeaturesBenchResult RunFeaturesBenchmark(const FeaturesBenchOptions& options,
                                         const Progress& progress = {});

}  // namespace uwscan::bench
