#include <gtest/gtest.h>

#include <fstream>
#include <set>

#include "mapping/log/dive_log.hpp"
#include "mapping/log/dive_log_test_support.hpp"

// Reading damaged, foreign and still-growing logs, and a writer killed mid-write.
namespace uwscan::mapping::test {
namespace {

// A log cut short (a copy or transfer interrupted): SQLite calls it malformed and reads nothing;
// the reader says it is truncated and by how much, and read as damaged it gives the frames that
// the pages left still hold, each one as written.
TEST_F(DiveLogTest, ATruncatedLogIsNamedAsSuchAndItsFramesCanBeRecovered) {
  const fs::path whole = WriteLog("whole.db", 200, 100);
  const fs::path cut = dir_ / "cut.db";
  fs::copy_file(whole, cut);
  const std::uintmax_t size = fs::file_size(whole);
  fs::resize_file(cut, size / 2);

  const std::string message = MessageOf([&] { DiveLogReader reader(cut); });
  EXPECT_NE(
      message.find("dive log '" + cut.string() + "' is truncated: " + std::to_string(size / 2) +
                   " bytes of the " + std::to_string(size) + " its header gives"),
      std::string::npos)
      << message;
  EXPECT_NE(message.find("uwscan log salvage"), std::string::npos) << message;

  const DiveLogReader reader(cut, DiveLogOpening::kDamaged);
  std::int64_t recovered = 0;
  std::set<std::int64_t> without_truth;
  const DiveLogCheck check = reader.Check(
      [&](const FrameRecord& frame, const GroundTruthRecord* truth) {
        ExpectSameFrame(TestFrame(frame.index, 100), frame);
        // Even frames were written with ground truth; the cut may have taken it and left the frame.
        if (truth != nullptr) {
          EXPECT_EQ(frame.index % 2, 0);
        } else if (frame.index % 2 == 0) {
          without_truth.insert(frame.index);
        }
        ++recovered;
      },
      {});
  // Each of those is named damaged in table ground_truth (as may be odd frames, whose lookup in
  // the cut table failed too).
  std::set<std::int64_t> truth_damaged;
  for (const DiveLogDamage& d : check.damage) {
    if (d.table == "ground_truth") truth_damaged.insert(d.row);
  }
  for (const std::int64_t index : without_truth) EXPECT_EQ(truth_damaged.count(index), 1u) << index;
  EXPECT_FALSE(check.ok());
  ASSERT_FALSE(check.integrity.empty());
  EXPECT_EQ(check.integrity.front().rfind("the file is truncated: ", 0), 0u)
      << check.integrity.front();
  EXPECT_EQ(recovered, check.frames_intact);
  EXPECT_GT(recovered, 20);
  EXPECT_LT(recovered, 200);

  // An intact log opens the same either way.
  const DiveLogCheck intact = DiveLogReader(whole, DiveLogOpening::kDamaged).Check({}, {});
  EXPECT_TRUE(intact.ok());
  EXPECT_EQ(intact.frames_intact, 200);
}

TEST_F(DiveLogTest, ReaderNamesTheFileAndWhatIsWrong) {
  auto expect = [](const fs::path& path, const std::string& expected) {
    const std::string message = MessageOf([&] { DiveLogReader reader(path); });
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
    EXPECT_NE(message.find(expected), std::string::npos) << message;
  };
  expect(dir_ / "missing.uwlog", "no such file");

  const fs::path text = dir_ / "notes.uwlog";
  { std::ofstream(text) << "this is not a database, just some text long enough to matter\n"; }
  expect(text, "not a SQLite database");

  const fs::path empty = dir_ / "empty.uwlog";
  { std::ofstream touch(empty); }
  expect(empty, "not a uwscan dive log");

  const fs::path other = dir_ / "other.sqlite";
  RawExec(other, "CREATE TABLE things (x)");
  expect(other, "not a uwscan dive log");

  const fs::path newer = WriteLog("newer.uwlog", 2, 3);
  const int next = kDiveLogSchemaVersion + 1;
  RawExec(newer,
          "UPDATE meta SET value = " + std::to_string(next) + " WHERE key = 'schema_version'");
  const std::string message = MessageOf([&] { DiveLogReader reader(newer); });
  EXPECT_EQ(message, "dive log '" + newer.string() + "' has schema version " +
                         std::to_string(next) + ", this uwscan reads 1 to " +
                         std::to_string(kDiveLogSchemaVersion));

  const fs::path no_noise = WriteLog("no_noise.uwlog", 2, 3);
  RawExec(no_noise, "DROP TABLE navigation_noise");
  expect(no_noise, "no table 'navigation_noise'");

  const fs::path no_nav = WriteLog("no_nav.uwlog", 2, 3);
  RawExec(no_nav, "DROP TABLE navigation");
  expect(no_nav, "no table 'navigation'");

  const fs::path no_column = WriteLog("no_column.uwlog", 2, 3);
  RawExec(no_column, "ALTER TABLE ground_truth DROP COLUMN object_ids");
  expect(no_column, "object_ids");

  const fs::path log = WriteLog("dive.uwlog", 3, 3);
  const DiveLogReader reader(log);
  for (std::int64_t index : {3, -1, 99}) {
    for (const std::string& m : {MessageOf([&] { reader.ReadFrame(index); }),
                                 MessageOf([&] { reader.ReadGroundTruth(index); })}) {
      EXPECT_NE(m.find("has no frame " + std::to_string(index)), std::string::npos) << m;
      EXPECT_NE(m.find(log.string()), std::string::npos) << m;
    }
  }
}

TEST_F(DiveLogTest, CorruptRowsNameTheFrameAndColumn) {
  struct Damage {
    const char* sql;
    int frame;
    const char* column;
  };
  const Damage damages[] = {
      {"UPDATE frames SET peaks_px = x'0102' WHERE frame_index = 1", 1, "peaks_px"},
      {"UPDATE frames SET time_s = 'soon' WHERE frame_index = 2", 2, "time_s"},
      {"UPDATE frames SET time_s = 9e999 WHERE frame_index = 2", 2, "time_s"},
      {"UPDATE frames SET command = 1e10 WHERE frame_index = 0", 0, "command"},
      {"UPDATE frames SET image = x'00' WHERE frame_index = 1", 1, "image"},
      {"UPDATE frames SET image_format = 7 WHERE frame_index = 1", 1, "image_format"},
      {"UPDATE frames SET image_width_px = NULL WHERE frame_index = 1", 1, "image_width_px"},
      {"UPDATE ground_truth SET points_W = x'00' WHERE frame_index = 2", 2, "points_W"},
      {"UPDATE ground_truth SET object_ids = x'0000000000000000' WHERE frame_index = 0", 0,
       "object_ids"},
      {"UPDATE ground_truth SET T_W_C_qw = 0, T_W_C_qx = 0, T_W_C_qy = 0, T_W_C_qz = 0 "
       "WHERE frame_index = 2",
       2, "T_W_C_q"},
  };
  int n = 0;
  for (const Damage& damage : damages) {
    const fs::path path = WriteLog(("damaged" + std::to_string(n++) + ".uwlog").c_str(), 4, 6);
    RawExec(path, damage.sql);
    const DiveLogReader reader(path);
    const bool truth_column = std::string(damage.sql).find("ground_truth") != std::string::npos;
    const std::string via_index = MessageOf([&] {
      if (truth_column) {
        reader.ReadGroundTruth(damage.frame);
      } else {
        reader.ReadFrame(damage.frame);
      }
    });
    const std::string via_stream =
        MessageOf([&] { reader.ForEachFrame([](const auto&, const auto*) {}, true); });
    for (const std::string& m : {via_index, via_stream}) {
      EXPECT_NE(m.find(path.string()), std::string::npos) << damage.sql << ": " << m;
      EXPECT_NE(m.find("frame " + std::to_string(damage.frame)), std::string::npos)
          << damage.sql << ": " << m;
      EXPECT_NE(m.find(damage.column), std::string::npos) << damage.sql << ": " << m;
    }
  }

  // A hole in the numbering is damage too.
  const fs::path holed = WriteLog("holed.uwlog", 4, 6);
  RawExec(holed, "DELETE FROM frames WHERE frame_index = 1");
  const std::string m =
      MessageOf([&] { DiveLogReader(holed).ForEachFrame([](const auto&, const auto*) {}, false); });
  EXPECT_NE(m.find("frame 1 is missing"), std::string::npos) << m;
}

TEST_F(DiveLogTest, DamagedFilesGiveErrorsNotCrashes) {
  const fs::path original = WriteLog("original.uwlog", 120, 200);
  ASSERT_EQ(ReadEverything(original), 120);
  const auto size = fs::file_size(original);
  ASSERT_GT(size, 100000u);  // checkpointed into the file when the writer closed

  // Cut in half: pages the schema points to are gone.
  const fs::path cut = dir_ / "cut.uwlog";
  fs::copy_file(original, cut);
  fs::resize_file(cut, size / 2);
  EXPECT_NE(MessageOf([&] { ReadEverything(cut); }).find(cut.string()), std::string::npos);

  // Cut inside the first page.
  const fs::path sliver = dir_ / "sliver.uwlog";
  fs::copy_file(original, sliver);
  fs::resize_file(sliver, 300);
  EXPECT_NE(MessageOf([&] { ReadEverything(sliver); }).find(sliver.string()), std::string::npos);

  // Random bytes.
  std::mt19937_64 rng(5);
  const fs::path noise = dir_ / "noise.uwlog";
  {
    std::ofstream out(noise, std::ios::binary);
    for (int k = 0; k < 65536; ++k) out.put(static_cast<char>(rng()));
  }
  EXPECT_NE(MessageOf([&] { ReadEverything(noise); }).find(noise.string()), std::string::npos);

  // Bytes scribbled over anywhere: reading may still succeed (a damaged peak value is a valid
  // double), but whatever fails must fail as uwscan::Error naming the file.
  int failures = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const fs::path scribbled = dir_ / ("scribbled" + std::to_string(trial) + ".uwlog");
    fs::copy_file(original, scribbled);
    {
      std::fstream io(scribbled, std::ios::in | std::ios::out | std::ios::binary);
      for (int k = 0; k < 8; ++k) {
        io.seekp(static_cast<std::streamoff>(rng() % size));
        for (int b = 0; b < 16; ++b) io.put(static_cast<char>(rng()));
      }
    }
    try {
      ReadEverything(scribbled);
    } catch (const Error& e) {
      ++failures;
      EXPECT_NE(std::string(e.what()).find(scribbled.string()), std::string::npos) << e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "trial " << trial << ": not a uwscan::Error: " << e.what();
    }
  }
  EXPECT_GT(failures, 0);  // the damage was seen at least sometimes
}

TEST_F(DiveLogTest, ReadsWhileTheWriterIsStillOpen) {
  const fs::path path = dir_ / "live.uwlog";
  DiveLogWriter writer(path, TestHeader());
  for (int i = 0; i < 5; ++i) writer.AppendFrame(TestFrame(i, 30));

  const DiveLogReader reader(path);
  EXPECT_EQ(reader.frame_count(), 5);
  EXPECT_FALSE(reader.vehicle_mount().has_value());
  for (int i = 5; i < 10; ++i) writer.AppendFrame(TestFrame(i, 30));
  writer.SetVehicleMount(TestPose(3));
  writer.AppendNavigation({1.0, TestPose(4)});
  EXPECT_EQ(reader.frame_count(), 10);
  ExpectSameFrame(TestFrame(7, 30), reader.ReadFrame(7));
  EXPECT_TRUE(reader.vehicle_mount().has_value());
  EXPECT_EQ(reader.ReadNavigation().size(), 1u);

  // A stream sees the frames committed when it started, even as the writer goes on.
  std::int64_t visited = 0;
  reader.ForEachFrame(
      [&](const FrameRecord& frame, const GroundTruthRecord*) {
        ExpectSameFrame(TestFrame(frame.index, 30), frame);
        writer.AppendFrame(TestFrame(writer.frame_count(), 30));
        ++visited;
      },
      true);
  EXPECT_EQ(visited, 10);
  EXPECT_EQ(reader.frame_count(), 20);

  // The writer closes while the reader is open: the log stays in WAL mode, whole.
  writer = DiveLogWriter(dir_ / "other.uwlog", TestHeader());
  EXPECT_TRUE(fs::exists(path.string() + "-wal"));
  EXPECT_EQ(reader.frame_count(), 20);
  ExpectSameFrame(TestFrame(19, 30), reader.ReadFrame(19));
  EXPECT_EQ(ReadEverything(path), 20);
}

// Frames of the killed writer: a 1 MB image makes writing, not preparing, take most of the
// time, so that the kill lands inside AppendFrame.
FrameRecord HeavyFrame(std::int64_t i) {
  FrameRecord frame = TestFrame(i, 500);
  LogImage image{1024, 512, LogPixelFormat::kMono16, std::vector<std::uint8_t>(1024 * 512 * 2)};
  for (std::size_t b = 0; b < image.bytes.size(); ++b) image.bytes[b] = std::uint8_t(b * 7 + i);
  frame.image = std::move(image);
  return frame;
}

// A writer killed while checkpointing: the file's header already gives the size the checkpoint
// was making, its last pages still only in the WAL. The log is whole (SQLite reads those pages
// from the WAL), and the check says so; the same header without the WAL is a truncated file.
TEST_F(DiveLogTest, AHeaderAheadOfItsPagesWithTheWalBesideItIsWhole) {
  const fs::path path = dir_ / "checkpointing.db";
  const fs::path copy = dir_ / "killed.db";
  {
    // 1 MB frames: SQLite checkpoints every 4 MB or so, so the file holds the first frames and
    // the WAL the last ones.
    DiveLogWriter writer(path, TestHeader());
    for (int i = 0; i < 6; ++i) writer.AppendFrame(HeavyFrame(i));
    // The files as a kill would leave them: the writer never closes them.
    fs::copy_file(path, copy);
    fs::copy_file(path.string() + "-wal", copy.string() + "-wal");
  }
  ASSERT_GT(fs::file_size(copy.string() + "-wal"), 32u);
  // The header's page count 10 pages past the file's end, made valid as SQLite writes it.
  std::fstream file(copy, std::ios::in | std::ios::out | std::ios::binary);
  unsigned char h[100];
  file.read(reinterpret_cast<char*>(h), sizeof h);
  const std::uint32_t page_bytes = (std::uint32_t(h[16]) << 8) | h[17];
  const std::uint32_t pages = static_cast<std::uint32_t>(fs::file_size(copy) / page_bytes) + 10;
  for (int k = 0; k < 4; ++k) {
    h[28 + k] = static_cast<unsigned char>(pages >> (24 - 8 * k));
    h[92 + k] = h[24 + k];  // version-valid-for = the change counter
  }
  file.seekp(0);
  file.write(reinterpret_cast<const char*>(h), sizeof h);
  file.close();

  const DiveLogCheck check = DiveLogReader(copy, DiveLogOpening::kDamaged).Check({}, {});
  EXPECT_TRUE(check.ok()) << (check.integrity.empty() ? "" : check.integrity.front());
  EXPECT_EQ(check.frames_intact, 6);
  fs::remove(copy.string() + "-wal");
  const DiveLogCheck without_wal = DiveLogReader(copy, DiveLogOpening::kDamaged).Check({}, {});
  ASSERT_FALSE(without_wal.integrity.empty());
  EXPECT_EQ(without_wal.integrity.front().rfind("the file is truncated: ", 0), 0u)
      << without_wal.integrity.front();
}

// Reports on the pipe between the killed writer and the test: 2i when frame i is about to be
// appended, 2i + 1 once it is committed.
constexpr std::int64_t Starting(std::int64_t i) { return 2 * i; }
constexpr std::int64_t Committed(std::int64_t i) { return 2 * i + 1; }

// The child appends frames until it is killed (or, should the test be stuck, a limit).
[[noreturn]] void AppendUntilKilled(const fs::path& path, int report_fd) {
  auto report = [report_fd](std::int64_t value) {
    if (::write(report_fd, &value, sizeof(value)) != sizeof(value)) ::_exit(3);
  };
  try {
    DiveLogWriter writer(path, TestHeader());
    for (std::int64_t i = 0; i < 1000; ++i) {
      const FrameRecord frame = HeavyFrame(i);
      const GroundTruthRecord truth = TestTruth(i, frame);
      report(Starting(i));
      report(Committed(writer.AppendFrame(frame, &truth)));
    }
  } catch (...) {
    ::_exit(2);
  }
  ::_exit(0);
}

TEST_F(DiveLogTest, AWriterKilledMidWriteLeavesEveryCommittedFrame) {
  const fs::path path = dir_ / "killed.uwlog";
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(fds[0]);
    AppendUntilKilled(path, fds[1]);
  }
  ::close(fds[1]);

  std::int64_t last_report = -1;  // reports come in order: 0, 1, 2, ...
  auto read_reports_until = [&](std::int64_t wanted) {
    std::int64_t report;
    while (last_report < wanted && ::read(fds[0], &report, sizeof(report)) == sizeof(report)) {
      EXPECT_EQ(report, last_report + 1);
      last_report = report;
    }
  };

  // Read from another process while its writer is appending.
  read_reports_until(Committed(20));
  ASSERT_EQ(last_report, Committed(20)) << "the writer process stopped early";
  {
    const DiveLogReader reader(path);
    EXPECT_GE(reader.frame_count(), 21);
    ExpectSameFrame(HeavyFrame(20), reader.ReadFrame(20));
  }

  // Killed while appending frame 40.
  read_reports_until(Starting(40));
  ASSERT_EQ(last_report, Starting(40)) << "the writer process stopped early";
  ASSERT_EQ(::kill(child, SIGKILL), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "child exited " << status;
  read_reports_until(std::numeric_limits<std::int64_t>::max());  // sent before it died
  ::close(fds[0]);
  const std::int64_t last_started = last_report / 2;
  const std::int64_t last_committed = last_report % 2 ? last_started : last_started - 1;
  // The writer never closed: what it committed is still in the WAL, not the database file.
  ASSERT_TRUE(fs::exists(path.string() + "-wal"));

  const DiveLogReader reader(path);
  const std::int64_t count = reader.frame_count();
  EXPECT_GE(count, last_committed + 1);
  EXPECT_LE(count, last_started + 1);  // the frame in progress may have made it, no more
  std::int64_t visited = 0;
  reader.ForEachFrame(
      [&](const FrameRecord& frame, const GroundTruthRecord* truth) {
        const FrameRecord expected = HeavyFrame(frame.index);
        ExpectSameFrame(expected, frame);
        ASSERT_NE(truth, nullptr);
        ExpectSameTruth(TestTruth(frame.index, expected), *truth);
        ++visited;
      },
      true);
  EXPECT_EQ(visited, count);
}

}  // namespace
}  // namespace uwscan::mapping::test
