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

// A merged order renumbers the keys; keys added after it are taken out newest first, and each
// state is checked against the keys that should be there, found or not, and their order.
TEST(VoxelIndex, KeysTakenOutNewestFirstAreGoneAndTheRestStillFound) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<std::int64_t> near(-30, 30);
  const auto draw = [&] {
    VoxelKey key;
    for (std::int64_t& k : key) k = near(rng);
    return key;
  };
  VoxelIndex index;
  for (int i = 0; i < 5000; ++i) index.Insert(draw());
  const std::vector<std::uint32_t> order = index.IdsByKey();
  std::vector<VoxelKey> kept;
  for (const std::uint32_t id : order) kept.push_back(index.key(id));
  index.Renumber(order, 0);
  for (std::uint32_t id = 0; id < kept.size(); ++id) {
    ASSERT_EQ(index.key(id), kept[id]);
    ASSERT_EQ(index.Find(kept[id]), std::int64_t{id});
  }
  // Enough new keys to grow the table on the way, then every one of them out again.
  std::vector<VoxelKey> added;
  for (int i = 0; i < 60000; ++i) {
    const VoxelKey key = draw();
    if (index.Insert(key) >= kept.size() + added.size()) added.push_back(key);
  }
  ASSERT_GT(added.size(), 20000u);
  for (std::size_t n = added.size(); n-- > 0;) {
    index.RemoveNewest();
    ASSERT_EQ(index.Find(added[n]), -1);
    if (n % 997 == 0) {
      for (std::uint32_t id = 0; id < kept.size(); ++id)
        ASSERT_EQ(index.Find(kept[id]), std::int64_t{id}) << "after taking out to " << n;
      for (std::size_t a = 0; a < n; ++a)
        ASSERT_EQ(index.Find(added[a]), std::int64_t(kept.size() + a));
    }
  }
  EXPECT_EQ(index.size(), kept.size());
  EXPECT_EQ(index.IdsByKey().size(), kept.size());
  // A key inserted again gets the next id, as a new one.
  EXPECT_EQ(index.Insert(added.front()), kept.size());
}

TEST(VoxelIndex, AMergeOrderIsAppliedInPlace) {
  // Ids 0..5 in order merged with new ids 6..9.
  const std::vector<std::uint32_t> old_ids = {6, 0, 1, 9, 2, 3, 7, 4, 8, 5};
  std::vector<int> values = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
  ApplyMergeOrder(old_ids, 6, values);
  EXPECT_EQ(values, (std::vector<int>{6, 0, 1, 9, 2, 3, 7, 4, 8, 5}));
}

}  // namespace
}  // namespace uwscan::perception
