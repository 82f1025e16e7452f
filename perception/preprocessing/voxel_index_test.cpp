#include "perception/preprocessing/voxel_index.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <random>
#include <vector>

namespace uwscan::perception {
namespace {

// Keys drawn with many repeats, negative and far-out coordinates among them, against a
// std::map numbering them in the order first seen; keys looked up, present or not.
TEST(VoxelIndex, NumbersKeysInTheOrderFirstSeenFindsThemAndSortsThemLikeStdMap) {
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<std::int64_t> near(-40, 40);
  std::map<VoxelKey, std::uint32_t> reference;
  VoxelIndex index;
  for (int i = 0; i < 200000; ++i) {
    VoxelKey key;
    for (std::int64_t& k : key) k = near(rng);
    if (i % 1000 == 0) key[i % 3] = (i % 2 ? 1 : -1) * (std::int64_t{1} << 61);
    const auto [it, added] = reference.emplace(key, static_cast<std::uint32_t>(reference.size()));
    ASSERT_EQ(index.Insert(key), it->second) << "draw " << i;
    ASSERT_EQ(index.size(), reference.size());
  }
  for (int i = 0; i < 20000; ++i) {
    VoxelKey key;
    for (std::int64_t& k : key) k = near(rng) * 2;  // many never inserted
    const auto it = reference.find(key);
    ASSERT_EQ(index.Find(key), it == reference.end() ? -1 : std::int64_t{it->second});
  }
  const std::vector<std::uint32_t> by_key = index.IdsByKey();
  ASSERT_EQ(by_key.size(), reference.size());
  std::size_t n = 0;
  for (const auto& [key, id] : reference) {
    EXPECT_EQ(by_key[n], id);
    EXPECT_EQ(index.key(by_key[n]), key);
    ++n;
  }
}

TEST(VoxelIndex, EmptyHasNoIds) {
  const VoxelIndex index;
  EXPECT_EQ(index.size(), 0u);
  EXPECT_EQ(index.Find({0, 0, 0}), -1);
  EXPECT_TRUE(index.IdsByKey().empty());
}

}  // namespace
}  // namespace uwscan::perception
