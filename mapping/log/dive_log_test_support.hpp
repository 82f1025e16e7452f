#pragma once

// What the dive log's tests share: test records, comparisons to the bit, raw SQL on a log, and
// a fixture with a folder of its own. Included by the *_test.cpp files of mapping/ only.

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
#include <functional>
#include <limits>
#include <random>
#include <string>

#include "mapping/log/dive_log.hpp"
#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::mapping::test {

namespace fs = std::filesystem;

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

inline DiveLogHeader TestHeader() {
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

inline Eigen::Isometry3d TestPose(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond{u(rng), u(rng), u(rng), u(rng)}.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d{100.0 * u(rng), -50.0 * u(rng), 1e-3 * u(rng)};
  return T;
}

// Frame i of every test log: deterministic, with awkward doubles, some frames with images.
inline FrameRecord TestFrame(std::int64_t i, int num_peaks) {
  std::mt19937_64 rng(static_cast<std::uint64_t>(i) + 1);
  std::uniform_real_distribution<double> u(0.0, 2048.0);
  FrameRecord frame;
  frame.time_s = 0.1 * static_cast<double>(i) + 1.0 / 3.0;
  frame.command = static_cast<int>(i % 201) - 100;
  frame.sweep = static_cast<int>(i / 201);
  for (int k = 0; k < num_peaks; ++k) frame.peaks_px.push_back({u(rng), u(rng)});
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

inline GroundTruthRecord TestTruth(std::int64_t i, const FrameRecord& frame) {
  GroundTruthRecord truth;
  truth.T_W_C = TestPose(1000 + static_cast<std::uint64_t>(i));
  for (std::size_t k = 0; k < frame.peaks_px.size(); ++k) {
    truth.points_W.emplace_back(frame.peaks_px[k].x() * 1e-3, 1.0 / (1.0 + double(k)), -2.5);
    truth.object_ids.push_back(static_cast<std::int32_t>(k % 4) - 1);
  }
  return truth;
}

// "2024-05-01T12:34:56Z"
inline bool IsIso8601Utc(const std::string& text) {
  const std::string pattern = "dddd-dd-ddTdd:dd:ddZ";
  if (text.size() != pattern.size()) return false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const bool ok = pattern[i] == 'd' ? std::isdigit(static_cast<unsigned char>(text[i])) != 0
                                      : text[i] == pattern[i];
    if (!ok) return false;
  }
  return true;
}

inline bool SameBits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

inline void ExpectSameFrame(const FrameRecord& expected, const FrameRecord& actual) {
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

inline void ExpectSamePose(const Eigen::Isometry3d& expected, const Eigen::Isometry3d& actual) {
  // Translation is stored as is; rotation goes through a unit quaternion (a few ulp).
  EXPECT_TRUE(expected.translation() == actual.translation());
  EXPECT_LT((expected.linear() - actual.linear()).cwiseAbs().maxCoeff(), 2e-15);
  EXPECT_LT((actual.linear().transpose() * actual.linear() - Eigen::Matrix3d::Identity()).norm(),
            1e-14);
}

inline void ExpectSameTruth(const GroundTruthRecord& expected, const GroundTruthRecord& actual) {
  ExpectSamePose(expected.T_W_C, actual.T_W_C);
  ASSERT_EQ(expected.points_W.size(), actual.points_W.size());
  for (std::size_t k = 0; k < expected.points_W.size(); ++k) {
    for (int a = 0; a < 3; ++a)
      EXPECT_TRUE(SameBits(expected.points_W[k][a], actual.points_W[k][a]));
  }
  EXPECT_EQ(expected.object_ids, actual.object_ids);
}

inline std::string MessageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no uwscan::Error thrown)";
}

// Edits a log behind the library's back, as damage or another program would.
inline void RawExec(const fs::path& path, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  char* error = nullptr;
  const int rc = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error);
  EXPECT_EQ(rc, SQLITE_OK) << sql << ": " << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close(db);
}

// Reads everything a log holds, as a replay would.
inline std::int64_t ReadEverything(const fs::path& path) {
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

}  // namespace uwscan::mapping::test
