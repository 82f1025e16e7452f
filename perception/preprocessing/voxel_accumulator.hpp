#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "perception/cloud/point_cloud.hpp"
#include "perception/preprocessing/voxel_index.hpp"

namespace uwscan::perception {

// VoxelDownsample one cloud at a time: clouds moved into a common frame are added as they come
// and only each voxel's sum and count are kept, so the memory is the voxels' (the area mapped),
// not the points' (a long dive's revisits). Cloud() gives the same bits as VoxelDownsample of all
// the added points (moved to float about `origin`, in the order added) would.
class VoxelAccumulator {
 public:
  // leaf_m > 0; origin: the merged cloud's, which its float points are relative to.
  VoxelAccumulator(double leaf_m, const Eigen::Vector3d& origin);
  // Adds `cloud`'s points moved by T (into the merged frame). Throws uwscan::Error on a
  // non-finite point or one whose voxel key overflows (as VoxelDownsample).
  void Add(const PointCloud& cloud, const Eigen::Isometry3d& T);
  // Each voxel's centroid, in VoxelDownsample's order (by voxel key), normals dropped.
  PointCloud Cloud() const;
  // The same into `out` (replacing what it held), whose storage is reused, with room to grow
  // when it had to grow: a live map built every few seconds then asks for no new block of the
  // map's size each time.
  void CloudInto(PointCloud& out) const;
  std::size_t voxel_count() const { return voxels_.size(); }

  // Marks the state that Undo returns to, bit for bit: what a live map needs to add the part of
  // a dive that may still move, publish, and take that part out again without a copy of the whole
  // map. Marks nest (at most 255): Undo returns to the newest and drops it. Each mark keeps the
  // sum of every voxel it changed as it was before, and takes the voxels it made out again.
  void Mark();
  void Undo();  // requires a mark
  std::size_t marks() const { return marks_.size(); }
  // Numbers the voxels in key order, so that Cloud() sorts only the voxels added afterwards.
  // Requires no mark (the kept sums are by voxel number).
  void OrderByKey();

 private:
  struct Sum {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::int64_t count = 0;
  };
  struct Saved {
    std::uint32_t id;
    std::uint8_t depth;  // saved_depth_[id] before it was saved here
    Sum sum;
  };
  // Every voxel id in key order: the key-ordered ones [0, key_ordered_) merged with the rest.
  std::vector<std::uint32_t> IdsByKey() const;
  // Calls visit(id) for each in that order, without a list of them all.
  template <typename Visit>
  void ForEachIdByKey(Visit&& visit) const;

  double leaf_m_;
  Eigen::Vector3d origin_;
  VoxelIndex voxels_;
  std::vector<Sum> sums_;          // by voxel id
  std::uint32_t key_ordered_ = 0;  // ids below it are numbered in key order
  struct MarkState {
    std::size_t first_saved;  // saved_[first_saved ..] were saved under this mark
    std::uint32_t voxels;     // voxel_count() at the mark: newer voxels are taken out, not saved
  };
  // An older voxel is saved under the newest mark once: when its saved_depth_ is below that
  // mark's depth (its place in marks_ + 1). A voxel is new at the depth it was made at.
  std::vector<MarkState> marks_;
  std::vector<Saved> saved_;
  std::vector<std::uint8_t> saved_depth_;  // by voxel id
};

}  // namespace uwscan::perception
