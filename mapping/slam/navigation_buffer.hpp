#pragma once

#include <Eigen/Geometry>
#include <deque>

#include "mapping/log/dive_log.hpp"

namespace uwscan::mapping {

// The navigation received so far, as an interpolating path: linear in position, slerp in
// rotation. Fed in time order, as a vehicle delivers it; older samples can be dropped so an
// online mapper holds a bounded window.
class NavigationBuffer {
 public:
  // Appends a sample. A sample at the time of the last one is ignored (it cannot be
  // interpolated towards); an earlier one, or a non-finite one, throws uwscan::Error.
  void Add(const NavigationRecord& record);

  bool empty() const { return samples_.empty(); }
  double first_time_s() const;
  double last_time_s() const;
  // True when t lies within [first, last] sample time.
  bool Covers(double time_s) const;
  // The time between the samples either side of time_s (0 at a sample's own time): how far
  // the interpolation has to reach. Throws uwscan::Error outside [first, last] or when empty.
  double GapAround(double time_s) const;
  // T_W_V at time_s; throws uwscan::Error outside [first, last] or when empty.
  Eigen::Isometry3d T_W_V(double time_s) const;
  // time_s held to [first, last] sample time, where the pose is known (the buffer must not be
  // empty): for frames at the very ends of a dive, a pose held at its nearest sample.
  double HeldTime(double time_s) const;
  // Forgets samples that no time >= time_s needs (keeps the one at or before it).
  void DropBefore(double time_s);

 private:
  void RequireCovered(double time_s) const;  // throws uwscan::Error naming the span
  std::deque<NavigationRecord> samples_;
};

}  // namespace uwscan::mapping
