#include "mapping/dive_log.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::mapping {
namespace {

namespace fs = std::filesystem;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

DiveLogHeader TestHeader() {
  DiveLogHeader header;
  header.scanner = scanner::DefaultScanner(scanner::ScannerKind::kGalvo);
  header.scanner.camera().camera.fx_px = 2400.5;
  scanner::StepRecord record;
  record.step = "intrinsics";
  record.dataset = "/data/ümlaut, tab\there";  // text of any kind goes through
  header.scanner.calibration.push_back(record);
  header.scan_pattern.kind = scanner::ScannerKind::kGalvo;
  header.scan_pattern.galvo.step_stride = 5;
  header.scene_yaml = "objects:\n  - shape: sphere\n";
  header.producer = "uwscan dive_log_test";
  return header;
}

Eigen::Isometry3d TestPose(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(100.0 * u(rng), -50.0 * u(rng), 1e-3 * u(rng));
  return T;
}

// Frame i of every test log: deterministic, with awkward doubles, some frames with images.
FrameRecord TestFrame(std::int64_t i, int num_peaks) {
  std::mt19937_64 rng(static_cast<std::uint64_t>(i) + 1);
  std::uniform_real_distribution<double> u(0.0, 2048.0);
  FrameRecord frame;
  frame.time_s = 0.1 * static_cast<double>(i) + 1.0 / 3.0;
  frame.command = static_cast<int>(i % 201) - 100;
  frame.sweep = static_cast<int>(i / 201);
  for (int k = 0; k < num_peaks; ++k) frame.peaks_px.emplace_back(u(rng), u(rng));
  if (num_peaks >= 2) {
    frame.peaks_px[0] = {-0.0, std::numeric_limits<double>::denorm_min()};
    frame.peaks_px[1] = {std::nextafter(1.0, 2.0), -1.5e300};
  }
  if (i % 3 == 1) {
    LogImage image;
    image.width_px = 17;
    image.height_px = 5;
    image.format = i % 2 ? LogPixelFormat::kMono16 : LogPixelFormat::kMono8;
    const int bytes_per_pixel = image.format == LogPixelFormat::kMono16 ? 2 : 1;
    image.bytes.resize(std::size_t(image.width_px * image.height_px * bytes_per_pixel));
    for (std::size_t b = 0; b < image.bytes.size(); ++b) image.bytes[b] = std::uint8_t(rng());
    frame.image = std::move(image);
  }
  return frame;
}

GroundTruthRecord TestTruth(std::int64_t i, const FrameRecord& frame) {
  GroundTruthRecord truth;
  truth.T_W_C = TestPose(1000 + static_cast<std::uint64_t>(i));
  for (std::size_t k = 0; k < frame.peaks_px.size(); ++k) {
    truth.points_W.emplace_back(frame.peaks_px[k].x() * 1e-3, 1.0 / (1.0 + double(k)), -2.5);
    truth.object_ids.push_back(static_cast<std::int32_t>(k % 4) - 1);
  }
  return truth;
}

// "2024-05-01T12:34:56Z"
bool IsIso8601Utc(const std::string& text) {
  const std::string pattern = "dddd-dd-ddTdd:dd:ddZ";
  if (text.size() != pattern.size()) return false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const bool ok = pattern[i] == 'd' ? std::isdigit(static_cast<unsigned char>(text[i])) != 0
                                      : text[i] == pattern[i];
    if (!ok) return false;
  }
  return true;
}

bool SameBits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

void ExpectSameFrame(const FrameRecord& expected, const FrameRecord& actual) {
  EXPECT_TRUE(SameBits(expected.time_s, actual.time_s)) << actual.index;
  EXPECT_EQ(expected.command, actual.command);
  EXPECT_EQ(expected.sweep, actual.sweep);
  ASSERT_EQ(expected.peaks_px.size(), actual.peaks_px.size()) << actual.index;
  for (std::size_t k = 0; k < expected.peaks_px.size(); ++k) {
    EXPECT_TRUE(SameBits(expected.peaks_px[k].x(), actual.peaks_px[k].x()) &&
                SameBits(expected.peaks_px[k].y(), actual.peaks_px[k].y()))
        << "frame " << actual.index << " peak " << k;
  }
  ASSERT_EQ(expected.image.has_value(), actual.image.has_value()) << actual.index;
  if (expected.image) {
    EXPECT_EQ(expected.image->width_px, actual.image->width_px);
    EXPECT_EQ(expected.image->height_px, actual.image->height_px);
    EXPECT_EQ(expected.image->format, actual.image->format);
    EXPECT_EQ(expected.image->bytes, actual.image->bytes);
  }
}

void ExpectSamePose(const Eigen::Isometry3d& expected, const Eigen::Isometry3d& actual) {
  // Translation is stored as is; rotation goes through a unit quaternion (a few ulp).
  EXPECT_TRUE(expected.translation() == actual.translation());
  EXPECT_LT((expected.linear() - actual.linear()).cwiseAbs().maxCoeff(), 2e-15);
  EXPECT_LT((actual.linear().transpose() * actual.linear() - Eigen::Matrix3d::Identity()).norm(),
            1e-14);
}

void ExpectSameTruth(const GroundTruthRecord& expected, const GroundTruthRecord& actual) {
  ExpectSamePose(expected.T_W_C, actual.T_W_C);
  ASSERT_EQ(expected.points_W.size(), actual.points_W.size());
  for (std::size_t k = 0; k < expected.points_W.size(); ++k) {
    for (int a = 0; a < 3; ++a)
      EXPECT_TRUE(SameBits(expected.points_W[k][a], actual.points_W[k][a]));
  }
  EXPECT_EQ(expected.object_ids, actual.object_ids);
}

std::string MessageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no uwscan::Error thrown)";
}

// Edits a log behind the library's back, as damage or another program would.
void RawExec(const fs::path& path, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  char* error = nullptr;
  const int rc = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error);
  EXPECT_EQ(rc, SQLITE_OK) << sql << ": " << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
}

// Reads everything a log holds, as a replay would.
std::int64_t ReadEverything(const fs::path& path) {
  DiveLogReader reader(path);
  std::int64_t visited = 0;
  reader.ForEachFrame([&](const FrameRecord&, const GroundTruthRecord*) { ++visited; }, true);
  reader.ReadNavigation();
  reader.vehicle_mount();
  for (std::int64_t i = 0; i < reader.frame_count(); ++i) {
    reader.ReadFrame(i);
    reader.ReadGroundTruth(i);
  }
  return visited;
}

class DiveLogTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("uwscan_dive_log_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A closed log of `frames` frames (every even one with truth) and a little navigation.
  fs::path WriteLog(const char* name, int frames, int num_peaks) {
    const fs::path path = dir_ / name;
    DiveLogWriter writer(path, TestHeader());
    for (int i = 0; i < frames; ++i) {
      const FrameRecord frame = TestFrame(i, num_peaks);
      const GroundTruthRecord truth = TestTruth(i, frame);
      writer.AppendFrame(frame, i % 2 == 0 ? &truth : nullptr);
    }
    writer.AppendNavigation({0.5, TestPose(7)});
    writer.SetVehicleMount(TestPose(8));
    return path;
  }

  fs::path dir_;
};

TEST_F(DiveLogTest, RoundTripsHeaderFramesTruthAndNavigation) {
  const fs::path path = dir_ / "dive.uwlog";
  const DiveLogHeader header = TestHeader();
  std::vector<FrameRecord> frames;
  std::vector<std::optional<GroundTruthRecord>> truths;
  {
    DiveLogWriter writer(path, header);
    EXPECT_EQ(writer.frame_count(), 0);
    for (int i = 0; i < 8; ++i) {
      FrameRecord frame = TestFrame(i, i == 0 ? 0 : 50 * i);
      frame.index = 1234;  // ignored: the writer numbers frames
      std::optional<GroundTruthRecord> truth;
      if (i % 2 == 0) truth = TestTruth(i, frame);
      EXPECT_EQ(writer.AppendFrame(frame, truth ? &*truth : nullptr), i);
      frame.index = i;
      frames.push_back(frame);
      truths.push_back(truth);
    }
    EXPECT_EQ(writer.frame_count(), 8);
    // Out of time order on purpose; equal times keep their append order.
    writer.AppendNavigation({2.0, TestPose(1)});
    writer.AppendNavigation({0.25, TestPose(2)});
    writer.AppendNavigation({2.0, TestPose(3)});
    writer.AppendNavigation({-1e-9, TestPose(4)});
    writer.SetVehicleMount(TestPose(5));
    writer.SetVehicleMount(TestPose(6));  // the last one stands
  }
  // The test frames must cover what they claim to.
  bool mono8 = false, mono16 = false;
  for (const FrameRecord& f : frames) {
    if (f.image) (f.image->format == LogPixelFormat::kMono8 ? mono8 : mono16) = true;
  }
  ASSERT_TRUE(mono8 && mono16);

  const DiveLogReader reader(path);
  EXPECT_EQ(reader.header().schema_version, kDiveLogSchemaVersion);
  EXPECT_EQ(scanner::ScannerToYaml(reader.header().scanner), scanner::ScannerToYaml(header.scanner));
  EXPECT_EQ(reader.header().scanner.calibration.at(0).dataset, "/data/ümlaut, tab\there");
  EXPECT_EQ(reader.header().scan_pattern.kind, scanner::ScannerKind::kGalvo);
  EXPECT_EQ(reader.header().scan_pattern.galvo.step_stride, 5);
  EXPECT_EQ(reader.header().scene_yaml, header.scene_yaml);
  EXPECT_EQ(reader.header().producer, header.producer);
  EXPECT_TRUE(IsIso8601Utc(reader.header().created_utc)) << reader.header().created_utc;
  ASSERT_TRUE(reader.vehicle_mount().has_value());
  ExpectSamePose(TestPose(6), *reader.vehicle_mount());

  ASSERT_EQ(reader.frame_count(), 8);
  for (int i = 0; i < 8; ++i) {
    const FrameRecord frame = reader.ReadFrame(i);
    EXPECT_EQ(frame.index, i);
    ExpectSameFrame(frames[std::size_t(i)], frame);
    const std::optional<GroundTruthRecord> truth = reader.ReadGroundTruth(i);
    ASSERT_EQ(truth.has_value(), truths[std::size_t(i)].has_value()) << i;
    if (truth) ExpectSameTruth(*truths[std::size_t(i)], *truth);
  }

  const std::vector<NavigationRecord> nav = reader.ReadNavigation();
  ASSERT_EQ(nav.size(), 4u);
  const double times[] = {-1e-9, 0.25, 2.0, 2.0};
  const std::uint64_t seeds[] = {4, 2, 1, 3};
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_TRUE(SameBits(nav[k].time_s, times[k])) << k;
    ExpectSamePose(TestPose(seeds[k]), nav[k].T_W_V);
  }
}

TEST_F(DiveLogTest, AClosedLogIsOneFileThatReadingLeavesAlone) {
  const fs::path path = WriteLog("dive.uwlog", 3, 10);
  auto files = [&] {
    std::vector<std::string> names;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir_)) {
      names.push_back(entry.path().filename().string());
    }
    return names;
  };
  EXPECT_EQ(files(), std::vector<std::string>{"dive.uwlog"});
  EXPECT_EQ(ReadEverything(path), 3);
  EXPECT_EQ(files(), std::vector<std::string>{"dive.uwlog"});
}

TEST_F(DiveLogTest, Mono16PixelsKeepTheirValues) {
  const fs::path path = dir_ / "mono16.uwlog";
  LogImage image;
  image.width_px = 3;
  image.height_px = 2;
  image.format = LogPixelFormat::kMono16;
  const std::uint16_t pixels[] = {0, 1, 255, 256, 0x1234, 65535};
  image.bytes.resize(sizeof(pixels));
  std::memcpy(image.bytes.data(), pixels, sizeof(pixels));
  FrameRecord frame;
  frame.image = image;
  DiveLogWriter(path, TestHeader()).AppendFrame(frame);

  const FrameRecord read = DiveLogReader(path).ReadFrame(0);
  ASSERT_TRUE(read.image.has_value());
  ASSERT_EQ(read.image->bytes.size(), sizeof(pixels));
  std::uint16_t read_pixels[6];
  std::memcpy(read_pixels, read.image->bytes.data(), sizeof(read_pixels));
  for (int k = 0; k < 6; ++k) EXPECT_EQ(read_pixels[k], pixels[k]);
  EXPECT_TRUE(read.peaks_px.empty());
}

TEST_F(DiveLogTest, ForEachFrameStreamsInIndexOrderWithOrWithoutTruth) {
  const fs::path path = WriteLog("dive.uwlog", 25, 40);
  const DiveLogReader reader(path);
  for (bool with_truth : {true, false}) {
    std::int64_t next = 0;
    reader.ForEachFrame(
        [&](const FrameRecord& frame, const GroundTruthRecord* truth) {
          EXPECT_EQ(frame.index, next);
          FrameRecord expected = TestFrame(next, 40);
          ExpectSameFrame(expected, frame);
          if (with_truth && next % 2 == 0) {
            ASSERT_NE(truth, nullptr) << next;
            ExpectSameTruth(TestTruth(next, expected), *truth);
          } else {
            EXPECT_EQ(truth, nullptr) << next;
          }
          // Re-entrant: the visitor may use the reader.
          EXPECT_EQ(reader.ReadFrame(frame.index).time_s, frame.time_s);
          ++next;
        },
        with_truth);
    EXPECT_EQ(next, 25);
  }
}

TEST_F(DiveLogTest, RefusesToOverwriteAnything) {
  const fs::path path = dir_ / "existing.uwlog";
  { std::ofstream(path) << "precious"; }
  EXPECT_NE(MessageOf([&] { DiveLogWriter(path, TestHeader()); }).find("already exists"),
            std::string::npos);
  std::ifstream in(path);
  std::string content;
  in >> content;
  EXPECT_EQ(content, "precious");

  // A second writer on a log being written.
  const fs::path live = dir_ / "live.uwlog";
  DiveLogWriter writer(live, TestHeader());
  writer.AppendFrame(TestFrame(0, 10));
  const std::string message = MessageOf([&] { DiveLogWriter(live, TestHeader()); });
  EXPECT_NE(message.find(live.string()), std::string::npos) << message;
  EXPECT_EQ(DiveLogReader(live).frame_count(), 1);

  // A journal left over from an earlier log would be replayed into the new file.
  const fs::path fresh = dir_ / "fresh.uwlog";
  { std::ofstream(fresh.string() + "-wal") << "stale"; }
  EXPECT_NE(MessageOf([&] { DiveLogWriter(fresh, TestHeader()); }).find("stray"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(fresh));
}

TEST_F(DiveLogTest, RefusesAnInvalidHeader) {
  DiveLogHeader header = TestHeader();
  header.scan_pattern.kind = scanner::ScannerKind::kMems;  // the scanner is a galvanometer
  EXPECT_NE(MessageOf([&] { DiveLogWriter(dir_ / "a.uwlog", header); }).find("header.scan_pattern"),
            std::string::npos);
  header = TestHeader();
  header.scanner.camera().camera.fx_px = -1.0;
  EXPECT_NE(MessageOf([&] { DiveLogWriter(dir_ / "b.uwlog", header); }).find("invalid header"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ / "a.uwlog"));
  EXPECT_FALSE(fs::exists(dir_ / "b.uwlog"));
}

TEST_F(DiveLogTest, RefusesNonFiniteOrInconsistentRecordsAndWritesNothing) {
  const fs::path path = dir_ / "dive.uwlog";
  DiveLogWriter writer(path, TestHeader());
  const FrameRecord good = TestFrame(0, 5);
  const GroundTruthRecord good_truth = TestTruth(0, good);

  auto refused = [&](const FrameRecord& frame, const GroundTruthRecord* truth,
                     const std::string& expected) {
    const std::string message = MessageOf([&] { writer.AppendFrame(frame, truth); });
    EXPECT_NE(message.find(expected), std::string::npos) << message;
    EXPECT_NE(message.find(path.string()), std::string::npos) << message;
    EXPECT_NE(message.find("frame 0"), std::string::npos) << message;
  };
  FrameRecord frame = good;
  frame.time_s = kNaN;
  refused(frame, nullptr, "time_s");
  frame = good;
  frame.time_s = std::numeric_limits<double>::infinity();
  refused(frame, nullptr, "time_s");
  frame = good;
  frame.peaks_px[3].y() = kNaN;
  refused(frame, nullptr, "peak 3");
  frame = good;
  frame.image = LogImage{4, 4, LogPixelFormat::kMono16, std::vector<std::uint8_t>(16)};
  refused(frame, nullptr, "image");
  frame.image = LogImage{0, 4, LogPixelFormat::kMono8, {}};
  refused(frame, nullptr, "image");
  GroundTruthRecord truth = good_truth;
  truth.T_W_C.translation().x() = kNaN;
  refused(good, &truth, "T_W_C");
  truth = good_truth;
  truth.T_W_C.linear() *= 2.0;
  refused(good, &truth, "rigid");
  truth = good_truth;
  truth.points_W.pop_back();
  refused(good, &truth, "one per peak");
  truth = good_truth;
  truth.object_ids.push_back(0);
  refused(good, &truth, "one per peak");
  truth = good_truth;
  truth.points_W[1].z() = -kNaN;
  refused(good, &truth, "point 1");

  EXPECT_NE(MessageOf([&] {
              writer.AppendNavigation({kNaN, Eigen::Isometry3d::Identity()});
            }).find("time_s"),
            std::string::npos);
  Eigen::Isometry3d reflection = Eigen::Isometry3d::Identity();
  reflection.linear().diagonal() << 1.0, 1.0, -1.0;
  EXPECT_NE(MessageOf([&] {
              writer.AppendNavigation({0.0, reflection});
            }).find("rigid"),
            std::string::npos);
  Eigen::Isometry3d nan_mount = Eigen::Isometry3d::Identity();
  nan_mount.linear()(0, 1) = kNaN;
  EXPECT_NE(MessageOf([&] { writer.SetVehicleMount(nan_mount); }).find("T_V_C"), std::string::npos);

  // Nothing of the refused records is in the log, and numbering goes on where it was.
  EXPECT_EQ(writer.frame_count(), 0);
  EXPECT_EQ(writer.AppendFrame(good, &good_truth), 0);
  const DiveLogReader reader(path);
  EXPECT_EQ(reader.frame_count(), 1);
  EXPECT_TRUE(reader.ReadNavigation().empty());
  EXPECT_FALSE(reader.vehicle_mount().has_value());
  ExpectSameFrame(good, reader.ReadFrame(0));
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
  RawExec(newer, "UPDATE meta SET value = 2 WHERE key = 'schema_version'");
  const std::string message = MessageOf([&] { DiveLogReader reader(newer); });
  EXPECT_EQ(message, "dive log '" + newer.string() + "' has schema version 2, this uwscan reads 1");

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
}  // namespace uwscan::mapping
