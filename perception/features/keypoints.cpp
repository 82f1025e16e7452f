#include "perception/features/keypoints.hpp"

#include <cmath>

#include "scanner/common/option_checks.hpp"

namespace uwscan::perception {

void CurvatureKeypointOptions::Check() const {
  OptionChecks("CurvatureKeypointOptions")
      .Require(min_curvature >= 0.0 && min_curvature <= 1.0 / 3.0, "min_curvature", "in [0, 1/3]",
               min_curvature);
}

std::vector<std::size_t> CurvatureKeypoints(std::span<const float> curvatures,
                                            const CurvatureKeypointOptions& options) {
  options.Check();
  std::vector<std::size_t> keypoints;
  for (std::size_t i = 0; i < curvatures.size(); ++i) {
    // False for NaN.
    if (static_cast<double>(curvatures[i]) > options.min_curvature) keypoints.push_back(i);
  }
  return keypoints;
}

}  // namespace uwscan::perception
