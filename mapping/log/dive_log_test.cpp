#include "mapping/log/dive_log.hpp"

#include <gtest/gtest.h>

#include "mapping/log/dive_log_test_support.hpp"

// Writing and reading a dive log: what goes in comes out, and what is refused.
namespace uwscan::mapping::test {
namespace {

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
  EXPECT_EQ(scanner::ScannerToYaml(reader.header().scanner),
            scanner::ScannerToYaml(header.scanner));
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

}  // namespace
}  // namespace uwscan::mapping::test
