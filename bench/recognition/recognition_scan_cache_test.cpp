#include "bench/recognition/recognition_scan_cache.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::bench {
namespace {

namespace fs = std::filesystem;

class ScanCache : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = fs::temp_directory_path() / ("uwscan-scan-cache-test-" + std::to_string(::getpid()));
    fs::remove_all(folder_);
  }
  void TearDown() override { fs::remove_all(folder_); }

  static scanner::sim::VirtualScan Scan() {
    scanner::sim::VirtualScan scan;
    for (int i = 0; i < 5; ++i) {
      scan.points_C.emplace_back(0.1 * i, -0.2 * i, 1.0 + 1e-7 * i);
      scan.object_index.push_back(i % 3 - 1);
    }
    return scan;
  }
  fs::path folder_;
};

TEST_F(ScanCache, AScanComesBackBitForBitUnderItsKey) {
  const CachedScanKey key{7, 0x1234};
  EXPECT_FALSE(LoadCachedScan(folder_, key));  // nothing saved yet
  const scanner::sim::VirtualScan scan = Scan();
  SaveCachedScan(folder_, key, scan);
  const auto loaded = LoadCachedScan(folder_, key);
  ASSERT_TRUE(loaded);
  EXPECT_EQ(loaded->points_C, scan.points_C);
  EXPECT_EQ(loaded->object_index, scan.object_index);
  // The same scan index with other settings is not taken for it.
  EXPECT_FALSE(LoadCachedScan(folder_, CachedScanKey{7, 0x1235}));
}

TEST_F(ScanCache, ADamagedFileIsRefusedNamingIt) {
  const CachedScanKey key{3, 99};
  SaveCachedScan(folder_, key, Scan());
  const fs::path file = folder_ / "scan_3.bin";
  ASSERT_TRUE(fs::exists(file));
  {  // flip one byte of a coordinate
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(40);
    f.put('\x7f');
  }
  try {
    LoadCachedScan(folder_, key);
    FAIL() << "a damaged cache file was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("scan_3.bin"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("checksum"), std::string::npos) << e.what();
  }
  fs::resize_file(file, 20);
  EXPECT_THROW(LoadCachedScan(folder_, key), Error);
}

}  // namespace
}  // namespace uwscan::bench
