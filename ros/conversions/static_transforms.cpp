#include "ros/conversions/static_transforms.hpp"

#include <deque>

namespace uwscan::ros {

void StaticTransforms::Add(const TransformMessage& t) {
  edges_[t.header.frame_id][t.child_frame_id] = t.transform;
  edges_[t.child_frame_id][t.header.frame_id] = t.transform.inverse();
}

std::optional<Eigen::Isometry3d> StaticTransforms::Find(const std::string& from,
                                                        const std::string& to) const {
  // Breadth first from `from`, composing T_from_frame along the way.
  std::map<std::string, Eigen::Isometry3d> T_from = {{from, Eigen::Isometry3d::Identity()}};
  std::deque<std::string> queue = {from};
  while (!queue.empty()) {
    const std::string frame = queue.front();
    queue.pop_front();
    if (frame == to) return T_from.at(frame);
    const auto edges = edges_.find(frame);
    if (edges == edges_.end()) continue;
    for (const auto& [next, T_frame_next] : edges->second) {
      if (T_from.count(next) > 0) continue;
      T_from[next] = T_from.at(frame) * T_frame_next;
      queue.push_back(next);
    }
  }
  return std::nullopt;
}

}  // namespace uwscan::ros
