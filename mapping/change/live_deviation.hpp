#pragma once

#include <Eigen/Core>
#include <memory>
#include <span>
#include <vector>

#include "mapping/change/survey.hpp"

namespace uwscan::mapping {

struct LiveDeviationOptions {
  double max_distance_m = 0.05;  // no reference point nearer: no value (NaN), > 0
  // |deviation| below this is drawn as no change (NaN): a single live point is noisier than the
  // averaged surfaces `compare` weighs against their level of detection. Metres, >= 0.
  double threshold_m = 0.003;
  double normal_radius_m = 0.025;  // the reference's normals where it has none, > 0
  void Check() const;
};

// What a map growing during a dive deviates from a reference, point by point, for colouring it
// live: the signed distance along the nearest reference point's normal (> 0 in front of the
// reference: material gained). The reference is in the map's frame. A reference without normals
// gets them from its neighbourhoods, turned up (NED: -z). The findings with their significance
// come afterwards from `compare`. Deviations may be asked from several threads at once.
class LiveDeviation {
 public:
  // Throws uwscan::Error when the reference is empty or the options are invalid.
  LiveDeviation(const Survey& reference, const LiveDeviationOptions& options = {});
  ~LiveDeviation();
  LiveDeviation(const LiveDeviation&) = delete;
  LiveDeviation& operator=(const LiveDeviation&) = delete;

  std::vector<float> Deviations(std::span<const Eigen::Vector3d> points_W) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace uwscan::mapping
