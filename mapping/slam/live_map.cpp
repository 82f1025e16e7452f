#include "mapping/slam/live_map.hpp"

#include <string>

#include "mapping/slam/mapper.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping {

LiveMap::LiveMap(double voxel_m, int settle_batch, int rebuild_batch)
    : voxel_m_(voxel_m), settle_batch_(settle_batch), rebuild_batch_(rebuild_batch) {
  if (!(voxel_m > 0.0)) throw Error("LiveMap: voxel_m must be > 0, got " + std::to_string(voxel_m));
  if (settle_batch < 1)
    throw Error("LiveMap: settle_batch must be > 0, got " + std::to_string(settle_batch));
  if (rebuild_batch < 0)
    throw Error("LiveMap: rebuild_batch must be >= 0, got " + std::to_string(rebuild_batch));
}

perception::PointCloud LiveMap::Build(const Mapper& mapper) {
  perception::PointCloud map;
  Build(mapper, map);
  return map;
}

void LiveMap::Build(const Mapper& mapper, perception::PointCloud& map) {
  if (mapper.submap_count() == 0) {
    map = {};
    return;
  }
  // Mapper::Map's origin is the first submap's place, which only a whole solve moves once the
  // submap is settled; a whole solve moves every submap merged so far.
  const bool moved = map_ && (mapper.stats().whole_solves != whole_solves_ ||
                              mapper.scan_pose(0).translation() != origin_);
  if (moved && rebuild_batch_ > 0) BeginRebuild(mapper);
  if (rebuild_) ContinueRebuild(mapper);
  if (!map_ || (moved && rebuild_batch_ == 0)) {
    Restart(mapper);
  } else if (mapper.FirstMovableSubmap() - settled_ >= settle_batch_) {
    Settle(mapper);
  } else {
    UndoMoved(mapper);
  }
  MergeMovable(mapper);
  map_->CloudInto(map);
}

void LiveMap::BeginRebuild(const Mapper& mapper) {
  const int whole_solves = mapper.stats().whole_solves;
  const Eigen::Vector3d origin = mapper.scan_pose(0).translation();
  if (rebuild_ && rebuild_->whole_solves == whole_solves && rebuild_->origin == origin) return;
  rebuild_.emplace(
      Rebuild{perception::VoxelAccumulator(voxel_m_, origin), whole_solves, origin, 0});
}

// Restart's work, spread over Builds: the same submaps added in the same order at the same
// places (settled ones do not move before the next whole solve), so the same map to the bit.
void LiveMap::ContinueRebuild(const Mapper& mapper) {
  Rebuild& r = *rebuild_;
  const int first_movable = mapper.FirstMovableSubmap();
  for (int n = 0; n < rebuild_batch_ && r.merged < first_movable; ++n, ++r.merged)
    r.map.Add(mapper.submap_clouds(r.merged)->cloud, mapper.scan_pose(r.merged));
  if (r.merged < first_movable) return;
  map_.emplace(std::move(r.map));
  map_->OrderByKey();
  map_->Mark();  // steady
  map_->Mark();  // recent
  settled_ = steady_ = r.merged;
  merged_poses_.clear();
  whole_solves_ = r.whole_solves;
  origin_ = r.origin;
  rebuild_.reset();
}

void LiveMap::Restart(const Mapper& mapper) {
  origin_ = mapper.scan_pose(0).translation();
  whole_solves_ = mapper.stats().whole_solves;
  map_.emplace(voxel_m_, origin_);
  settled_ = 0;
  Settle(mapper);
}

void LiveMap::Settle(const Mapper& mapper) {
  while (map_->marks() > 0) map_->Undo();
  for (const int first_movable = mapper.FirstMovableSubmap(); settled_ < first_movable; ++settled_)
    map_->Add(mapper.submap_clouds(settled_)->cloud, mapper.scan_pose(settled_));
  map_->OrderByKey();
  map_->Mark();  // steady
  map_->Mark();  // recent
  steady_ = settled_;
  merged_poses_.clear();
}

void LiveMap::UndoMoved(const Mapper& mapper) {
  const int merged_end = settled_ + static_cast<int>(merged_poses_.size());
  int first_moved = settled_;
  while (first_moved < merged_end &&
         mapper.scan_pose(first_moved).matrix() == merged_poses_[first_moved - settled_].matrix())
    ++first_moved;
  if (first_moved == merged_end) return;
  map_->Undo();  // recent: [steady_, merged_end)
  if (first_moved < steady_) {
    map_->Undo();  // steady: [settled_, steady_)
    map_->Mark();
    steady_ = settled_;
  }
  // Under the steady mark again: the submaps that did not move, at their same places.
  for (; steady_ < first_moved; ++steady_)
    map_->Add(mapper.submap_clouds(steady_)->cloud, merged_poses_[steady_ - settled_]);
  map_->Mark();
  merged_poses_.resize(static_cast<std::size_t>(first_moved - settled_));
}

void LiveMap::MergeMovable(const Mapper& mapper) {
  for (int i = settled_ + static_cast<int>(merged_poses_.size()); i < mapper.submap_count(); ++i) {
    const Eigen::Isometry3d pose = mapper.scan_pose(i);
    map_->Add(mapper.submap_clouds(i)->cloud, pose);
    merged_poses_.push_back(pose);
  }
}

}  // namespace uwscan::mapping
