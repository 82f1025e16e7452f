#pragma once

#include <Eigen/Geometry>
#include <map>
#include <optional>
#include <string>

#include "ros/bridge/messages.hpp"

namespace uwscan::ros {

// The static transforms (/tf_static) seen so far, as a tree in which to find the transform
// between any two of its frames.
class StaticTransforms {
 public:
  void Add(const TransformMessage& transform);
  // T_from_to through the tree; std::nullopt when the two frames are not connected.
  std::optional<Eigen::Isometry3d> Find(const std::string& from, const std::string& to) const;

 private:
  std::map<std::string, std::map<std::string, Eigen::Isometry3d>> edges_;  // edges_[a][b] = T_a_b
};

}  // namespace uwscan::ros
