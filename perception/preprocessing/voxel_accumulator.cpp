#include "perception/preprocessing/voxel_accumulator.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <string>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::perception {

VoxelAccumulator::VoxelAccumulator(double leaf_m, const Eigen::Vector3d& origin)
    : leaf_m_(leaf_m), origin_(origin) {
  if (!(leaf_m > 0.0) || !std::isfinite(leaf_m))
    throw Error("VoxelAccumulator: leaf_m must be finite and > 0, got " + std::to_string(leaf_m));
  if (!origin.allFinite()) throw Error("VoxelAccumulator: the origin must be finite");
}

void VoxelAccumulator::Add(const PointCloud& cloud, const Eigen::Isometry3d& T) {
  constexpr double kMaxKey = 4.611686018427387904e18;  // 2^62, as VoxelDownsample
  // Relative to the merged origin in double, then stored in float, as a merged cloud would be.
  const Eigen::Isometry3d T_relative = Eigen::Translation3d(-origin_) * T;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f p = (T_relative * cloud.Point(i)).cast<float>();
    const Eigen::Vector3d absolute = origin_ + p.cast<double>();
    if (!absolute.allFinite())
      throw Error("VoxelAccumulator: point " + std::to_string(i) + " is not finite");
    VoxelKey key;
    for (int a = 0; a < 3; ++a) {
      const double k = std::floor(absolute[a] / leaf_m_);
      if (!(std::abs(k) < kMaxKey)) {
        throw Error("VoxelAccumulator: leaf_m " + std::to_string(leaf_m_) +
                    " m is too small for coordinate " + std::to_string(absolute[a]) +
                    " m (voxel key overflows 64 bits)");
      }
      key[static_cast<std::size_t>(a)] = static_cast<std::int64_t>(k);
    }
    const std::uint32_t id = voxels_.Insert(key);
    // resize, not emplace_back: a failed allocation leaves no id without its sum.
    const auto depth = static_cast<std::uint8_t>(marks_.size());
    if (id >= sums_.size()) {
      sums_.resize(id + std::size_t{1});
      saved_depth_.resize(sums_.size(), depth);
    }
    Sum& voxel = sums_[id];
    if (saved_depth_[id] < depth) {
      saved_.push_back({id, saved_depth_[id], voxel});
      saved_depth_[id] = depth;
    }
    voxel.sum += p.cast<double>();
    ++voxel.count;
  }
}

template <typename Visit>
void VoxelAccumulator::ForEachIdByKey(Visit&& visit) const {
  const std::vector<std::uint32_t> rest = voxels_.IdsByKey(key_ordered_);
  // The ordered ids are 0, 1, ..., key_ordered_ - 1: merged with the rest without reading a list.
  std::uint32_t ordered = 0;
  std::size_t next = 0;
  while (ordered < key_ordered_ || next < rest.size()) {
    const bool take_rest = next < rest.size() &&
                           (ordered == key_ordered_ ||
                            VoxelIndex::KeyBefore(voxels_.key(rest[next]), voxels_.key(ordered)));
    visit(take_rest ? rest[next++] : ordered++);
  }
}

PointCloud VoxelAccumulator::Cloud() const {
  PointCloud out;
  CloudInto(out);
  return out;
}

void VoxelAccumulator::CloudInto(PointCloud& out) const {
  out.origin = origin_;
  out.points.clear();
  out.normals.clear();
  out.intensity.clear();
  // A cloud given again (a live map's, every few seconds) has grown since: room for half as
  // much again, so that it is not asked for anew each time.
  const std::size_t n = sums_.size();
  if (out.points.capacity() < n) out.points.reserve(out.points.capacity() == 0 ? n : n + n / 2);
  ForEachIdByKey([&](std::uint32_t id) {
    out.points.push_back((sums_[id].sum / static_cast<double>(sums_[id].count)).cast<float>());
  });
}

std::vector<std::uint32_t> VoxelAccumulator::IdsByKey() const {
  std::vector<std::uint32_t> ids;
  ids.reserve(voxels_.size());
  ForEachIdByKey([&](std::uint32_t id) { ids.push_back(id); });
  return ids;
}

void VoxelAccumulator::OrderByKey() {
  assert(marks_.empty());
  if (key_ordered_ == voxels_.size()) return;
  // In place: a copy of the whole map is what a live map must not need.
  const std::vector<std::uint32_t> old_ids = IdsByKey();
  voxels_.Renumber(old_ids, key_ordered_);
  ApplyMergeOrder(old_ids, key_ordered_, sums_);
  key_ordered_ = static_cast<std::uint32_t>(voxels_.size());
}

void VoxelAccumulator::Mark() {
  if (marks_.size() == 255) throw Error("VoxelAccumulator: more than 255 marks");
  marks_.push_back({saved_.size(), static_cast<std::uint32_t>(voxels_.size())});
}

void VoxelAccumulator::Undo() {
  assert(!marks_.empty());
  const MarkState mark = marks_.back();
  for (std::size_t i = mark.first_saved; i < saved_.size(); ++i) {
    sums_[saved_[i].id] = saved_[i].sum;
    saved_depth_[saved_[i].id] = saved_[i].depth;
  }
  saved_.resize(mark.first_saved);
  // Newest first: the only order in which VoxelIndex takes keys out.
  while (voxels_.size() > mark.voxels) voxels_.RemoveNewest();
  sums_.resize(mark.voxels);
  saved_depth_.resize(mark.voxels);
  marks_.pop_back();
  assert(key_ordered_ <= voxels_.size());  // ordered before any mark, so never taken out
}

}  // namespace uwscan::perception
