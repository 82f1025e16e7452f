#pragma once

#include <cstdint>
#include <filesystem>
#include <list>
#include <memory>
#include <vector>

#include "perception/cloud/point_cloud.hpp"

namespace uwscan::mapping {
class SpillFile;
}  // namespace uwscan::mapping

namespace uwscan::mapping {

// A submap's two clouds (Submap::cloud and Submap::sparse).
struct SubmapClouds {
  perception::PointCloud cloud;   // voxelised at the map voxel, with normals
  perception::PointCloud sparse;  // voxelised at the registration voxel
};

// The clouds of a dive's submaps, so that a long dive's memory does not grow with it: the newest
// `resident` submaps' clouds stay in memory, older ones are written once to a spill file in
// `spill_folder` (a SpillFile: it has no name there and goes with the store, or with the process)
// and read back when asked for (a loop closure's target, the map at the end), the last few read
// kept in memory. Without a spill folder every cloud stays in memory. Clouds come back with the
// same bits. Not thread-safe (the Mapper's thread only).
class SubmapStore {
 public:
  static constexpr int kReadBackCache = 8;  // clouds read back and kept (a loop's three, twice)

  // resident > 0. Throws uwscan::Error when the spill file cannot be created.
  SubmapStore(const std::filesystem::path& spill_folder, int resident);
  ~SubmapStore();
  SubmapStore(const SubmapStore&) = delete;
  SubmapStore& operator=(const SubmapStore&) = delete;

  // Adds the next submap's clouds (index size()).
  void Add(SubmapClouds clouds);
  // Submap `index`'s clouds, in [0, size()). Throws uwscan::Error when the spill file cannot be
  // read back.
  std::shared_ptr<const SubmapClouds> Get(int index) const;
  int size() const { return static_cast<int>(slots_.size()); }
  // The bytes of the clouds held in memory now (points, normals and intensities).
  std::int64_t memory_bytes() const;

 private:
  struct Slot {
    std::shared_ptr<const SubmapClouds> clouds;  // null once spilled
    std::int64_t offset = -1;                    // in the spill file once spilled
    std::int64_t bytes = 0;                      // its record's length there
  };
  void Spill(int index);

  std::unique_ptr<SpillFile> spill_;  // null: no spilling
  int resident_;
  std::vector<Slot> slots_;
  mutable std::list<std::pair<int, std::shared_ptr<const SubmapClouds>>> read_back_;
};

}  // namespace uwscan::mapping
