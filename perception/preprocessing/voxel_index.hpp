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
  // The ids from `first` on, ordered by key: the part a caller that keeps the first ones in
  // key order (Renumber) still has to sort.
  std::vector<std::uint32_t> IdsByKey(std::uint32_t first) const;
  // Takes the newest key out (id size() - 1), as if it had never been inserted; it must have been
  // inserted after the last Renumber. With linear probing the last key placed lies on no other
  // key's probe path (they were all placed before its slot was filled), so taking keys out newest
  // first breaks no path.
  void RemoveNewest();
  // Numbers the keys anew: the key of id old_ids[i] gets id i, `old_ids` being a merge order
  // (ApplyMergeOrder). The keys keep their slots.
  void Renumber(const std::vector<std::uint32_t>& old_ids, std::uint32_t first_new);
  static bool KeyBefore(const VoxelKey& a, const VoxelKey& b);  // lexicographic: x, y, z

 private:
  void Grow();
  std::vector<std::uint32_t> slots_;  // 1 + the id of the key stored there; 0: empty
  std::vector<VoxelKey> keys_;        // by id
};

// Moves values[old_ids[i]] to values[i], in place but for the new ones: `old_ids` is a merge
// order, a permutation of 0 .. n - 1 in which the ids below `first_new` appear in increasing order
// (ids already in order merged with new ones). Such an id comes from position i or before it, so
// filling the positions from the back reads none that was already overwritten.
template <typename T>
void ApplyMergeOrder(const std::vector<std::uint32_t>& old_ids, std::uint32_t first_new,
                     std::vector<T>& values) {
  const std::vector<T> new_ones(values.begin() + first_new, values.end());
  for (std::size_t i = old_ids.size(); i-- > 0;) {
    const std::uint32_t id = old_ids[i];
    values[i] = id < first_new ? values[id] : new_ones[id - first_new];
  }
}

}  // namespace uwscan::perception
