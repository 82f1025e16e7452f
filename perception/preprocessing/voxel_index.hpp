#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace uwscan::perception {

// A voxel's integer coordinates: floor(x / leaf) along each axis.
using VoxelKey = std::array<std::int64_t, 3>;

// Voxel keys numbered in the order they are first seen (0, 1, ...), so that points can be
// grouped by voxel with one probe each instead of a comparison sort of all of them (a submap's
// points outnumber its voxels several times). An open-addressing table with linear probing,
// kept at most half full, over flat arrays. Not thread-safe for Insert; Find is const.
class VoxelIndex {
 public:
  // The number of `key`; a key seen for the first time gets size() (before the call). Throws
  // uwscan::Error beyond 2^32 - 2 keys.
  std::uint32_t Insert(const VoxelKey& key);
  // The number of `key`, or -1 when it was never inserted.
  std::int64_t Find(const VoxelKey& key) const;
  std::size_t size() const { return keys_.size(); }
  const VoxelKey& key(std::uint32_t id) const { return keys_[id]; }
  // Every id, ordered by its key (lexicographically: x, then y, then z).
  std::vector<std::uint32_t> IdsByKey() const;

 private:
  void Grow();
  std::vector<std::uint32_t> slots_;  // 1 + the id of the key stored there; 0: empty
  std::vector<VoxelKey> keys_;        // by id
};

}  // namespace uwscan::perception
