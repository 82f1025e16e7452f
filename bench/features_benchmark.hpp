#pragma once

#include <filesystem>

#include "bench/progress.hpp"
#include "bench/registration_pairs.hpp"

namespace uwscan::bench {

// FPFH and ESF, uwscan's against PCL's, on the registration benchmark's object views: time per
// cloud, and how close uwscan's ESF comes to PCL's (chi-square distance), beside how far two
// runs of PCL's ESF land from each other (its clock-seeded sampling: the noise floor).
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
  double esf_chi2_to_pcl = 0.0;       // mean chi-square(uwscan, PCL)
  double esf_chi2_pcl_to_pcl = 0.0;   // mean chi-square(PCL, PCL run again)
};

FeaturesBenchResult RunFeaturesBenchmark(const FeaturesBenchOptions& options,
                                         const Progress& progress = {});

}  // namespace uwscan::bench
