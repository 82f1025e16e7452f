#include "mapping/slam/navigation_buffer.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {

void NavigationBuffer::Add(const NavigationRecord& record) {
  if (!std::isfinite(record.time_s) || !record.T_W_V.matrix().allFinite()) {
    throw Error("navigation: a sample with a non-finite time or pose");
  }
  if (!samples_.empty()) {
    const double last = samples_.back().time_s;
    if (record.time_s == last) return;
    if (record.time_s < last) {
      throw Error("navigation: sample at " + std::to_string(record.time_s) +
                  " s arrived after one at " + std::to_string(last) + " s (expected time order)");
    }
  }
  samples_.push_back(record);
}

double NavigationBuffer::first_time_s() const {
  if (samples_.empty()) throw Error("navigation: no sample yet");
  return samples_.front().time_s;
}

double NavigationBuffer::HeldTime(double time_s) const {
  return std::clamp(time_s, first_time_s(), last_time_s());
}

double NavigationBuffer::last_time_s() const {
  if (samples_.empty()) throw Error("navigation: no sample yet");
  return samples_.back().time_s;
}

bool NavigationBuffer::Covers(double time_s) const {
  return !samples_.empty() && time_s >= samples_.front().time_s && time_s <= samples_.back().time_s;
}

void NavigationBuffer::RequireCovered(double time_s) const {
  if (Covers(time_s)) return;
  throw Error("navigation: no sample brackets time " + std::to_string(time_s) + " s" +
              (samples_.empty() ? std::string(" (no navigation)")
                                : " (navigation spans " + std::to_string(first_time_s()) + " to " +
                                      std::to_string(last_time_s()) + " s)"));
}

double NavigationBuffer::GapAround(double time_s) const {
  RequireCovered(time_s);
  const auto after =
      std::lower_bound(samples_.begin(), samples_.end(), time_s,
                       [](const NavigationRecord& r, double t) { return r.time_s < t; });
  if (after->time_s == time_s) return 0.0;
  return after->time_s - (after - 1)->time_s;
}

Eigen::Isometry3d NavigationBuffer::T_W_V(double time_s) const {
  RequireCovered(time_s);
  const auto after =
      std::lower_bound(samples_.begin(), samples_.end(), time_s,
                       [](const NavigationRecord& r, double t) { return r.time_s < t; });
  if (after->time_s == time_s || after == samples_.begin()) return after->T_W_V;
  const NavigationRecord& a = *(after - 1);
  const NavigationRecord& b = *after;
  const double s = (time_s - a.time_s) / (b.time_s - a.time_s);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(a.T_W_V.linear())
                   .slerp(s, Eigen::Quaterniond(b.T_W_V.linear()))
                   .toRotationMatrix();
  T.translation() = (1.0 - s) * a.T_W_V.translation() + s * b.T_W_V.translation();
  return T;
}

void NavigationBuffer::DropBefore(double time_s) {
  while (samples_.size() > 1 && samples_[1].time_s <= time_s) samples_.pop_front();
}

}  // namespace uwscan::mapping
