#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

#include "mapping/log/dive_log.hpp"
#include "mapping/log/dive_log_test_support.hpp"

// Schema version 3: a checksum per column of every row, so that damage that keeps a value's
// type (a changed digit, a flipped bit in a blob) is named on read, found by Check, and left
// behind by a salvage.
namespace uwscan::mapping::test {
namespace {

// Flips the lowest bit of byte `byte` of a blob column in place: damage the checksums do not
// know of, as a bad sector or a stray write would make it.
void FlipBlobBit(const fs::path& path, const std::string& table, const std::string& column,
                 const std::string& where, int byte) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* select = nullptr;
  const std::string select_sql = "SELECT " + column + " FROM " + table + " WHERE " + where;
  ASSERT_EQ(sqlite3_prepare_v2(db, select_sql.c_str(), -1, &select, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_step(select), SQLITE_ROW);
  const auto* data = static_cast<const std::uint8_t*>(sqlite3_column_blob(select, 0));
  std::vector<std::uint8_t> blob(data, data + sqlite3_column_bytes(select, 0));
  sqlite3_finalize(select);
  ASSERT_LT(std::size_t(byte), blob.size());
  blob[std::size_t(byte)] ^= 1;
  sqlite3_stmt* update = nullptr;
  const std::string update_sql = "UPDATE " + table + " SET " + column + " = ? WHERE " + where;
  ASSERT_EQ(sqlite3_prepare_v2(db, update_sql.c_str(), -1, &update, nullptr), SQLITE_OK);
  sqlite3_bind_blob(update, 1, blob.data(), int(blob.size()), SQLITE_TRANSIENT);
  ASSERT_EQ(sqlite3_step(update), SQLITE_DONE);
  sqlite3_finalize(update);
  sqlite3_close(db);
}

TEST_F(DiveLogTest, ChecksumsNameTheRowAndColumnOfDamageThatKeepsTheType) {
  struct Damage {
    std::string sql;
    std::string where;   // names the row in the message
    std::string column;  // named in the message
  };
  const std::vector<Damage> damages = {
      {"UPDATE frames SET time_s = time_s + 1e-9 WHERE frame_index = 3", "frame 3", "time_s"},
      {"UPDATE frames SET command = command + 1 WHERE frame_index = 2", "frame 2", "command"},
      {"UPDATE frames SET sweep = 1 WHERE frame_index = 0", "frame 0", "sweep"},
      {"UPDATE frames SET image_width_px = 85, image_height_px = 1 WHERE frame_index = 1",
       "frame 1", "image_width_px"},
      {"UPDATE ground_truth SET T_W_C_tz = T_W_C_tz + 0.001 WHERE frame_index = 2", "frame 2",
       "T_W_C_tz"},
      {"UPDATE frames SET checksums = zeroblob(36) WHERE frame_index = 3", "frame 3",
       "frame_index"},
      {"UPDATE frames SET checksums = x'00' WHERE frame_index = 3", "frame 3", "checksums"},
  };
  int n = 0;
  for (const Damage& damage : damages) {
    const fs::path path = WriteLog(("typed" + std::to_string(n++) + ".uwlog").c_str(), 5, 8);
    RawExec(path, damage.sql);
    const DiveLogReader reader(path);
    const std::string m =
        MessageOf([&] { reader.ForEachFrame([](const auto&, const auto*) {}, true); });
    EXPECT_NE(m.find(path.string()), std::string::npos) << damage.sql << ": " << m;
    EXPECT_NE(m.find(damage.where + ":"), std::string::npos) << damage.sql << ": " << m;
    EXPECT_NE(m.find("column " + damage.column), std::string::npos) << damage.sql << ": " << m;
  }

  // One bit of a blob: a peak, a pixel, a true point.
  const fs::path peaks = WriteLog("peaks.uwlog", 5, 8);
  FlipBlobBit(peaks, "frames", "peaks_px", "frame_index = 4", 37);
  EXPECT_NE(MessageOf([&] { DiveLogReader(peaks).ReadFrame(4); }).find("frame 4: column peaks_px"),
            std::string::npos);
  const fs::path pixels = WriteLog("pixels.uwlog", 5, 8);
  FlipBlobBit(pixels, "frames", "image", "frame_index = 1", 11);
  EXPECT_NE(MessageOf([&] { DiveLogReader(pixels).ReadFrame(1); }).find("frame 1: column image"),
            std::string::npos);
  const fs::path points = WriteLog("points.uwlog", 5, 8);
  FlipBlobBit(points, "ground_truth", "points_W", "frame_index = 4", 100);
  EXPECT_NE(
      MessageOf([&] { DiveLogReader(points).ReadGroundTruth(4); }).find("frame 4: column points_W"),
      std::string::npos);

  // The navigation, the vehicle mount and the header.
  const fs::path nav = WriteLog("nav.uwlog", 2, 8);
  RawExec(nav, "UPDATE navigation SET T_W_V_tx = T_W_V_tx * 1.0000001");
  EXPECT_NE(MessageOf([&] { DiveLogReader(nav).ReadNavigation(); }).find("column T_W_V_tx"),
            std::string::npos);
  const fs::path mount = WriteLog("mount.uwlog", 2, 8);
  RawExec(mount, "UPDATE header SET T_V_C_ty = T_V_C_ty + 0.01");
  EXPECT_NE(MessageOf([&] { DiveLogReader reader(mount); }).find("column T_V_C_ty"),
            std::string::npos);
  const fs::path header = WriteLog("header.uwlog", 2, 8);
  RawExec(header, "UPDATE header SET scanner_yaml = replace(scanner_yaml, '2400.5', '2401.5')");
  EXPECT_NE(
      MessageOf([&] { DiveLogReader reader(header); }).find("table header: column scanner_yaml"),
      std::string::npos);
}

TEST_F(DiveLogTest, LogsOfEarlierSchemaVersionsStillRead) {
  const fs::path path = WriteLog("version2.uwlog", 4, 6);
  // What a version 2 writer made: the same tables without the checksums.
  for (const char* table : {"header", "frames", "ground_truth", "navigation"}) {
    RawExec(path, std::string("ALTER TABLE ") + table + " DROP COLUMN checksums");
  }
  RawExec(path, "UPDATE meta SET value = 2 WHERE key = 'schema_version'");
  const DiveLogReader reader(path);
  EXPECT_EQ(reader.header().schema_version, 2);
  EXPECT_EQ(ReadEverything(path), 4);
  EXPECT_TRUE(reader.vehicle_mount().has_value());
  EXPECT_EQ(reader.ReadNavigation().size(), 1u);
  const DiveLogCheck check = reader.Check({}, {});
  EXPECT_FALSE(check.checksummed);
  EXPECT_TRUE(check.ok());
  EXPECT_EQ(check.frames_intact, 4);
}

// A checksummed log of `frames` test frames (10 peaks each), each with its ground truth and a
// navigation record at 0.1 s steps.
void WriteTestDive(const fs::path& path, int frames) {
  DiveLogWriter writer(path, TestHeader());
  for (int i = 0; i < frames; ++i) {
    const FrameRecord frame = TestFrame(i, 10);
    const GroundTruthRecord truth = TestTruth(i, frame);
    writer.AppendFrame(frame, &truth);
    writer.AppendNavigation({0.1 * i, TestPose(50 + i)});
  }
}

TEST_F(DiveLogTest, CheckFindsEveryDamagedRowAndHandsOverEveryIntactOne) {
  const fs::path path = dir_ / "dive.uwlog";
  WriteTestDive(path, 12);
  EXPECT_TRUE(DiveLogReader(path).Check({}, {}).ok());

  FlipBlobBit(path, "frames", "peaks_px", "frame_index = 3", 20);
  RawExec(path, "UPDATE ground_truth SET T_W_C_qx = -T_W_C_qx WHERE frame_index = 7");
  RawExec(path, "UPDATE navigation SET time_s = time_s + 1 WHERE nav_id = 5");
  RawExec(path, "DELETE FROM frames WHERE frame_index = 9");

  const DiveLogReader reader(path);
  std::vector<std::int64_t> intact_frames;
  int intact_navigation = 0;
  const DiveLogCheck check = reader.Check(
      [&](const FrameRecord& frame, const GroundTruthRecord* truth) {
        ExpectSameFrame(TestFrame(frame.index, 10), frame);
        EXPECT_EQ(truth == nullptr, frame.index == 7);  // its ground truth is damaged
        intact_frames.push_back(frame.index);
      },
      [&](const NavigationRecord&) { ++intact_navigation; });
  EXPECT_TRUE(check.checksummed);
  EXPECT_FALSE(check.ok());
  EXPECT_TRUE(check.integrity.empty());  // SQLite's structure is fine: only values changed
  EXPECT_EQ(check.frames, 11);
  EXPECT_EQ(check.frames_intact, 10);
  EXPECT_EQ(check.frames_with_damaged_truth, 1);
  EXPECT_EQ(intact_frames, (std::vector<std::int64_t>{0, 1, 2, 4, 5, 6, 7, 8, 10, 11}));
  EXPECT_EQ(check.navigation, 12);
  EXPECT_EQ(check.navigation_intact, 11);
  EXPECT_EQ(intact_navigation, 11);
  ASSERT_EQ(check.damage.size(), 4u);
  const std::vector<std::pair<std::string, std::int64_t>> expected = {
      {"frames", 3}, {"ground_truth", 7}, {"frames", 9}, {"navigation", 5}};
  for (std::size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(check.damage[k].table, expected[k].first) << check.damage[k].message;
    EXPECT_EQ(check.damage[k].row, expected[k].second) << check.damage[k].message;
  }
  EXPECT_NE(check.damage[0].message.find("column peaks_px"), std::string::npos);
  EXPECT_NE(check.damage[1].message.find("column T_W_C_qx"), std::string::npos);
  EXPECT_NE(check.damage[2].message.find("frame 9 is missing"), std::string::npos);
  EXPECT_NE(check.damage[3].message.find("column time_s"), std::string::npos);
}

// Single-bit damage at random anywhere in the file, 300 times over: whatever the reader hands
// over as intact is exactly what was written (a damaged row is never returned as good), and what
// it cannot read it refuses with an error, never a crash.
TEST_F(DiveLogTest, NoFlippedBitAnywhereIsHandedOverAsAnIntactRow) {
  const fs::path whole = dir_ / "whole.uwlog";
  WriteTestDive(whole, 20);
  std::string bytes;
  {
    std::ifstream in(whole, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  ASSERT_GT(bytes.size(), 4096u);
  std::mt19937_64 rng(7);
  int damage_found = 0, refused = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::string flipped = bytes;
    const std::size_t at = std::uniform_int_distribution<std::size_t>(0, bytes.size() - 1)(rng);
    flipped[at] = static_cast<char>(flipped[at] ^ (1 << (rng() % 8)));
    const fs::path path = dir_ / "flipped.uwlog";
    {
      std::ofstream out(path, std::ios::binary | std::ios::trunc);
      out.write(flipped.data(), static_cast<std::streamsize>(flipped.size()));
    }
    SCOPED_TRACE("byte " + std::to_string(at));
    try {
      const DiveLogCheck check = DiveLogReader(path).Check(
          [](const FrameRecord& frame, const GroundTruthRecord* truth) {
            ExpectSameFrame(TestFrame(frame.index, 10), frame);
            if (truth != nullptr) ExpectSameTruth(TestTruth(frame.index, frame), *truth);
          },
          [](const NavigationRecord& nav) {
            const long i = std::lround(nav.time_s / 0.1);
            EXPECT_TRUE(SameBits(nav.time_s, 0.1 * static_cast<double>(i)));
            ExpectSamePose(TestPose(static_cast<std::uint64_t>(50 + i)), nav.T_W_V);
          });
      damage_found += !check.ok();
    } catch (const Error&) {
      ++refused;
    }
    fs::remove(path);
  }
  // A third of the flips land in rows or in SQLite's structure and are found (here 92 by Check,
  // 14 refused on opening); the rest fall in the pages' free space.
  EXPECT_GT(damage_found + refused, 50) << damage_found << " found, " << refused << " refused";
}

}  // namespace
}  // namespace uwscan::mapping::test
