#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace uwscan::perception {

struct CurvatureKeypointOptions {
  // Surface variation l0 / (l0 + l1 + l2) a point must exceed to be a keypoint; in [0, 1/3]
  // (0 on a plane, 1/3 for an isotropic neighbourhood).
  double min_curvature = 0.01;

  // Throws uwscan::Error naming the field when it is out of range.
  void Check() const;
};

// Keypoints by curvature (the seed's keypoint extraction: after plane removal, points whose
// surface variation (Pauly et al. 2002) is at or below the threshold are dropped): the
// increasing indices i with curvatures[i] > min_curvature. NaN curvatures (no normal) are
// never keypoints. Curvatures come from EstimateNormals (NormalsResult::curvatures or
// CloudWithNormals::curvatures).
std::vector<std::size_t> CurvatureKeypoints(std::span<const float> curvatures,
                                            const CurvatureKeypointOptions& options);

}  // namespace uwscan::perception
