#pragma once

#include <optional>
#include <vector>

#include "perception/cloud/point_cloud.hpp"
#include "perception/preprocessing/voxel_accumulator.hpp"

namespace uwscan::mapping {

class Mapper;

// The map of a dive as it grows (what a live node publishes every few seconds), without merging
// every submap again each time: Mapper::Map reads back and voxelises all of them, a cost that grows
// with the dive. Three parts, merged in Mapper::Map's order so that the map is the same to the
// bit:
// - settled: the submaps no solve can move any more until the next whole-graph solve
//   (Mapper::FirstMovableSubmap), merged once for good, taken up in batches;
// - steady: movable submaps that have not moved since they were merged, under a mark;
// - recent: from the first submap that moved since the last map on (after most submaps, the
//   windowed solve's last few dozen; after a loop, up to all movable ones), under a second mark,
//   taken out (VoxelAccumulator::Undo) and merged again at their new places.
// The map is never copied. After a whole-graph solve (every submap moved) it is merged anew;
// those solves come at a fixed growth of the graph, so the work per submap stays bounded. On a
// long dive that is every settled submap read back and merged (seconds at half an hour): with a
// rebuild_batch the new settled part is merged that many submaps per Build beside the old one,
// which serves until it is complete.
class LiveMap {
 public:
  // voxel_m > 0 (Mapper::Map's). Settled submaps are taken up settle_batch (> 0) at a time:
  // each time every mark is undone (voxels are put in key order only without marks) and the
  // movable submaps are merged again, so a larger batch costs that less often, and keeps more
  // sums saved under the marks. rebuild_batch >= 0: after a whole-graph solve, the settled
  // submaps merged anew per Build (until then Build keeps the old settled part, with the movable
  // submaps at their new places); 0: all of them in the Build after the solve.
  explicit LiveMap(double voxel_m, int settle_batch = 100, int rebuild_batch = 0);
  // Mapper::Map(voxel_m) of `mapper` as it stands, unless rebuilding() (then the settled part is
  // where the last whole-graph solve but one placed it). Always called with the same mapper.
  perception::PointCloud Build(const Mapper& mapper);
  // The same into `map` (replacing what it held), whose storage is reused.
  void Build(const Mapper& mapper, perception::PointCloud& map);
  // Whether the settled part is being merged anew after a whole-graph solve (rebuild_batch).
  bool rebuilding() const { return rebuild_.has_value(); }

 private:
  // The settled part merged anew after a whole-graph solve, a batch per Build.
  struct Rebuild {
    perception::VoxelAccumulator map;
    int whole_solves = 0;
    Eigen::Vector3d origin;
    int merged = 0;  // submaps [0, merged) are in `map`
  };
  // Starts a Rebuild, or restarts it when another whole solve came meanwhile.
  void BeginRebuild(const Mapper& mapper);
  // Merges the next batch; once every settled submap is in, the rebuilt map replaces map_.
  void ContinueRebuild(const Mapper& mapper);

  void Restart(const Mapper& mapper);
  void Settle(const Mapper& mapper);
  // Takes out the merged movable submaps from the first one placed differently now on.
  void UndoMoved(const Mapper& mapper);
  void MergeMovable(const Mapper& mapper);

  // Submaps [0, settled_) merged for good, then [settled_, steady_) under the first mark and
  // [steady_, settled_ + merged_poses_.size()) under the second.
  std::optional<perception::VoxelAccumulator> map_;
  int settled_ = 0, steady_ = 0;
  std::vector<Eigen::Isometry3d> merged_poses_;  // of the movable submaps merged, from settled_
  int whole_solves_ = 0;                         // the mapper's count when map_ was started
  Eigen::Vector3d origin_;                       // map_'s: the first submap's place then
  double voxel_m_;
  int settle_batch_;
  int rebuild_batch_;
  std::optional<Rebuild> rebuild_;
};

}  // namespace uwscan::mapping
