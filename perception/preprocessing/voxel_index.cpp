#include "perception/preprocessing/voxel_index.hpp"

#include <algorithm>
#include <limits>
#include <numeric>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

// Element by element: std::array's own comparisons call memcmp.
bool SameKey(const VoxelKey& a, const VoxelKey& b) {
  return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

bool KeyBefore(const VoxelKey& a, const VoxelKey& b) {
  if (a[0] != b[0]) return a[0] < b[0];
  if (a[1] != b[1]) return a[1] < b[1];
  return a[2] < b[2];
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

std::vector<std::uint32_t> VoxelIndex::IdsByKey() const {
  std::vector<std::uint32_t> ids(keys_.size());
  std::iota(ids.begin(), ids.end(), 0u);
  std::sort(ids.begin(), ids.end(),
            [&](std::uint32_t a, std::uint32_t b) { return KeyBefore(keys_[a], keys_[b]); });
  return ids;
}

}  // namespace uwscan::perception
