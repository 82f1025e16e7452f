#include "mapping/slam/submap_store.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cstdint>
#include <filesystem>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

namespace fs = std::filesystem;

// Submap i's clouds: n points and normals whose values say which submap and point they are.
SubmapClouds Clouds(int i, std::size_t n) {
  SubmapClouds c;
  c.cloud.origin = Eigen::Vector3d(i, 0.5 * i, -0.25 * i);
  c.sparse.origin = c.cloud.origin;
  for (std::size_t k = 0; k < n; ++k) {
    const float v = static_cast<float>(i) + 1e-4f * static_cast<float>(k);
    c.cloud.points.emplace_back(v, -v, 0.5f * v);
    c.cloud.normals.emplace_back(0.0f, 0.6f, 0.8f);
    if (k % 3 == 0) c.sparse.points.emplace_back(v, v, v);
  }
  return c;
}

void ExpectSameBits(const perception::PointCloud& a, const perception::PointCloud& b) {
  ASSERT_EQ(a.origin, b.origin);
  ASSERT_EQ(a.points.size(), b.points.size());
  ASSERT_EQ(a.normals.size(), b.normals.size());
  for (std::size_t k = 0; k < a.points.size(); ++k) {
    for (int d = 0; d < 3; ++d)
      ASSERT_EQ(std::bit_cast<std::uint32_t>(a.points[k][d]),
                std::bit_cast<std::uint32_t>(b.points[k][d]));
  }
  for (std::size_t k = 0; k < a.normals.size(); ++k) ASSERT_EQ(a.normals[k], b.normals[k]);
}

class SubmapStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("uwscan_submap_store_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(SubmapStoreTest, SpilledCloudsComeBackWithTheSameBits) {
  SubmapStore store(dir_, 4);
  for (int i = 0; i < 30; ++i) store.Add(Clouds(i, 100 + static_cast<std::size_t>(i)));
  ASSERT_EQ(store.size(), 30);
  // Out of order, and twice, so that some come from the read-back cache.
  for (const int i : {0, 29, 3, 17, 0, 25, 26, 12, 3}) {
    const SubmapClouds expected = Clouds(i, 100 + static_cast<std::size_t>(i));
    const std::shared_ptr<const SubmapClouds> got = store.Get(i);
    ExpectSameBits(got->cloud, expected.cloud);
    ExpectSameBits(got->sparse, expected.sparse);
  }
}

// A long synthetic stream: the memory the store holds stays at the resident submaps and the
// read-back cache, however many submaps come.
TEST_F(SubmapStoreTest, MemoryStaysUnderItsBoundOnALongStream) {
  constexpr int kResident = 16;
  constexpr std::size_t kPoints = 2000;
  const SubmapClouds one = Clouds(0, kPoints);
  const std::int64_t per_submap = static_cast<std::int64_t>(
      (one.cloud.points.capacity() + one.cloud.normals.capacity() + one.sparse.points.capacity()) *
      sizeof(Eigen::Vector3f));
  const std::int64_t bound = (kResident + SubmapStore::kReadBackCache) * per_submap;
  SubmapStore store(dir_, kResident);
  std::int64_t largest = 0;
  for (int i = 0; i < 3000; ++i) {
    store.Add(Clouds(i, kPoints));
    if (i % 7 == 0 && i > 100) store.Get(i - 100);  // a loop reading an old submap back
    if (i % 50 == 0) largest = std::max(largest, store.memory_bytes());
  }
  EXPECT_LE(largest, bound);
  EXPECT_GT(largest, kResident * per_submap / 2);  // the resident ones are really held
  // Without a spill folder everything stays.
  SubmapStore in_memory({}, kResident);
  for (int i = 0; i < 100; ++i) in_memory.Add(Clouds(i, kPoints));
  EXPECT_GE(in_memory.memory_bytes(), 100 * per_submap);
}

// The spill is a SpillFile (spill_file_test: nameless, gone with its owner or its process).
TEST_F(SubmapStoreTest, TheSpillFileIsNeverNamedInItsFolder) {
  SubmapStore store(dir_, 1);
  for (int i = 0; i < 5; ++i) store.Add(Clouds(i, 10));
  EXPECT_TRUE(fs::is_empty(dir_));
  ExpectSameBits(store.Get(0)->cloud, Clouds(0, 10).cloud);
}

TEST_F(SubmapStoreTest, AFolderItCannotWriteToIsNamed) {
  try {
    SubmapStore store(dir_ / "missing", 4);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos) << e.what();
  }
  SubmapStore store(dir_, 2);
  EXPECT_THROW(store.Get(0), Error);
  EXPECT_THROW(SubmapStore(dir_, 0), Error);
}

}  // namespace
}  // namespace uwscan::mapping
