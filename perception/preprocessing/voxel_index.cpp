#include "perception/preprocessing/voxel_index.hpp"

#include <algorithm>
#include <cassert>
#include <limits>
#include <numeric>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

// Element by element: std::array's own comparisons call memcmp.
bool SameKey(const VoxelKey& a, const VoxelKey& b) {
  return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

// Neighbouring voxels spread over the whole table: each axis by its own large odd multiplier,
// then SplitMix64's finaliser, whose low bits (the slot) depend on every bit of the key.
std::uint64_t Hash(const VoxelKey& k) {
  std::uint64_t h = static_cast<std::uint64_t>(k[0]) * 0x9E3779B97F4A7C15ull ^
                    static_cast<std::uint64_t>(k[1]) * 0xC2B2AE3D27D4EB4Full ^
                    static_cast<std::uint64_t>(k[2]) * 0x165667B19E3779F9ull;
  h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
  h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
  return h ^ (h >> 31);
}

}  // namespace

bool VoxelIndex::KeyBefore(const VoxelKey& a, const VoxelKey& b) {
  if (a[0] != b[0]) return a[0] < b[0];
  if (a[1] != b[1]) return a[1] < b[1];
  return a[2] < b[2];
}

std::uint32_t VoxelIndex::Insert(const VoxelKey& key) {
  if (2 * (keys_.size() + 1) > slots_.size()) Grow();
  const std::size_t mask = slots_.size() - 1;
  for (std::size_t s = Hash(key) & mask;; s = (s + 1) & mask) {
    const std::uint32_t slot = slots_[s];
    if (slot == 0) {
      if (keys_.size() == std::numeric_limits<std::uint32_t>::max() - 1)
        throw Error("VoxelIndex: more than 2^32 - 2 voxels");
      keys_.push_back(key);
      slots_[s] = static_cast<std::uint32_t>(keys_.size());
      return static_cast<std::uint32_t>(keys_.size() - 1);
    }
    if (SameKey(keys_[slot - 1], key)) return slot - 1;
  }
}

std::int64_t VoxelIndex::Find(const VoxelKey& key) const {
  if (slots_.empty()) return -1;
  const std::size_t mask = slots_.size() - 1;
  for (std::size_t s = Hash(key) & mask;; s = (s + 1) & mask) {
    const std::uint32_t slot = slots_[s];
    if (slot == 0) return -1;
    if (SameKey(keys_[slot - 1], key)) return slot - 1;
  }
}

void VoxelIndex::Grow() {
  slots_.assign(std::max<std::size_t>(64, 2 * slots_.size()), 0);
  const std::size_t mask = slots_.size() - 1;
  for (std::size_t id = 0; id < keys_.size(); ++id) {
    std::size_t s = Hash(keys_[id]) & mask;
    while (slots_[s] != 0) s = (s + 1) & mask;
    slots_[s] = static_cast<std::uint32_t>(id + 1);
  }
}

std::vector<std::uint32_t> VoxelIndex::IdsByKey() const { return IdsByKey(0); }

std::vector<std::uint32_t> VoxelIndex::IdsByKey(std::uint32_t first) const {
  std::vector<std::uint32_t> ids(keys_.size() - std::min<std::size_t>(first, keys_.size()));
  std::iota(ids.begin(), ids.end(), first);
  std::sort(ids.begin(), ids.end(),
            [&](std::uint32_t a, std::uint32_t b) { return KeyBefore(keys_[a], keys_[b]); });
  return ids;
}

void VoxelIndex::RemoveNewest() {
  assert(!keys_.empty());
  const std::size_t mask = slots_.size() - 1;
  const auto newest = static_cast<std::uint32_t>(keys_.size());  // its slot's value
  std::size_t s = Hash(keys_.back()) & mask;
  while (slots_[s] != newest) s = (s + 1) & mask;
  slots_[s] = 0;
  keys_.pop_back();
}

void VoxelIndex::Renumber(const std::vector<std::uint32_t>& old_ids, std::uint32_t first_new) {
  assert(old_ids.size() == keys_.size());
  std::vector<std::uint32_t> new_id(keys_.size());
  for (std::uint32_t i = 0; i < old_ids.size(); ++i) new_id[old_ids[i]] = i;
  ApplyMergeOrder(old_ids, first_new, keys_);
  // The slots no longer say in which order the keys were inserted, which RemoveNewest does not
  // need: every key inserted from now on is placed after all of these.
  for (std::uint32_t& slot : slots_)
    if (slot != 0) slot = new_id[slot - 1] + 1;
}

}  // namespace uwscan::perception
