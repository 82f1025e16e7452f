#pragma once

#include <optional>

#include "perception/cloud/point_cloud.hpp"
#include "perception/preprocessing/voxel_accumulator.hpp"

namespace uwscan::mapping {

class Mapper;

// The map of a dive as it grows (what a live node publishes every few seconds), without merging
// every submap again each time: Mapper::Map reads back and voxelises all of them, a cost that grows
// with the dive (on a 30-minute dive, every submap's cloud read back from the spill file twice a
// minute). The submaps no solve can move any more until the next whole-graph solve
// (Mapper::FirstMovableSubmap) are merged once and kept; each map adds the rest to a copy of them.
// Submaps are merged in the same order as Mapper::Map, so the map is the same to the bit. After a
// whole-graph solve (every submap moved) the kept part is merged again; those solves come at a
// fixed growth of the graph, so the merging per submap stays constant on average.
class LiveMap {
 public:
  explicit LiveMap(double voxel_m);  // voxel_m > 0 (Mapper::Map's)
  // Mapper::Map(voxel_m) of `mapper` as it stands. Always called with the same mapper.
  perception::PointCloud Build(const Mapper& mapper);

 private:
  double voxel_m_;
  std::optional<perception::VoxelAccumulator> settled_;  // submaps [0, settled_submaps_)
  int settled_submaps_ = 0;
  int whole_solves_ = 0;  // the mapper's count when settled_ was started
};

}  // namespace uwscan::mapping
