#include "mapping/inspection/frame_recorder.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include "mapping/log/dive_log_test_support.hpp"

namespace uwscan::mapping::test {
namespace {

// A queue far smaller than the frames: Push() waits for the writer, and still every frame
// pushed is in the log, in order, bit for bit.
TEST(FrameRecorder, WritesEveryFrameInOrderEvenWithATinyQueue) {
  const fs::path path =
      fs::temp_directory_path() / ("uwscan_frame_recorder_" + std::to_string(getpid()) + ".db");
  fs::remove(path);
  const int frames = 60;
  {
    FrameRecorder recorder(DiveLogWriter(path, TestHeader()), 1000);
    for (int i = 0; i < frames; ++i) recorder.Push(TestFrame(i, 50 + i));
    recorder.Finish();
    const FrameRecorderStatistics s = recorder.statistics();
    EXPECT_EQ(s.frames_written, frames);
    EXPECT_EQ(s.queued_bytes, 0u);
    EXPECT_THROW(recorder.Push(TestFrame(0, 1)), Error);
  }
  const DiveLogReader reader(path);
  ASSERT_EQ(reader.frame_count(), frames);
  for (int i = 0; i < frames; ++i) {
    const FrameRecord f = reader.ReadFrame(i);
    const FrameRecord expected = TestFrame(i, 50 + i);
    ASSERT_EQ(f.peaks_px.size(), expected.peaks_px.size());
    EXPECT_EQ(f.time_s, expected.time_s);
    EXPECT_EQ(f.command, expected.command);
    for (std::size_t k = 0; k < f.peaks_px.size(); ++k)
      EXPECT_EQ(f.peaks_px[k], expected.peaks_px[k]);
  }
  fs::remove(path);
}

TEST(FrameRecorder, AWriteErrorReachesThePusher) {
  const fs::path path =
      fs::temp_directory_path() / ("uwscan_frame_recorder_bad_" + std::to_string(getpid()) + ".db");
  fs::remove(path);
  FrameRecorder recorder(DiveLogWriter(path, TestHeader()), 1 << 20);
  FrameRecord bad = TestFrame(0, 3);
  bad.time_s = kNaN;  // the writer rejects it
  recorder.Push(bad);
  EXPECT_THROW(recorder.Finish(), Error);
  fs::remove(path);
}

}  // namespace
}  // namespace uwscan::mapping::test
