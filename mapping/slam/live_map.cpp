#include "mapping/slam/live_map.hpp"

#include <string>

#include "mapping/slam/mapper.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping {

LiveMap::LiveMap(double voxel_m) : voxel_m_(voxel_m) {
  if (!(voxel_m > 0.0)) throw Error("LiveMap: voxel_m must be > 0, got " + std::to_string(voxel_m));
}

perception::PointCloud LiveMap::Build(const Mapper& mapper) {
  const int count = mapper.submap_count();
  if (count == 0) return {};
  if (settled_ && mapper.stats().whole_solves != whole_solves_) {
    settled_.reset();  // a whole solve moved every submap merged so far
    settled_submaps_ = 0;
  }
  const int settle_up_to = mapper.FirstMovableSubmap();
  if (!settled_ && settle_up_to > 0) {
    // Mapper::Map's origin: the first submap's place, which no windowed solve moves once settled.
    settled_.emplace(voxel_m_, mapper.scan_pose(0).translation());
    whole_solves_ = mapper.stats().whole_solves;
  }
  for (; settled_submaps_ < settle_up_to; ++settled_submaps_)
    settled_->Add(mapper.submap_clouds(settled_submaps_)->cloud,
                  mapper.scan_pose(settled_submaps_));
  perception::VoxelAccumulator map =
      settled_ ? *settled_
               : perception::VoxelAccumulator(voxel_m_, mapper.scan_pose(0).translation());
  for (int i = settled_submaps_; i < count; ++i)
    map.Add(mapper.submap_clouds(i)->cloud, mapper.scan_pose(i));
  return map.Cloud();
}

}  // namespace uwscan::mapping
