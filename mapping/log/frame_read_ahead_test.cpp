#include "mapping/log/frame_read_ahead.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mapping/log/dive_log_test_support.hpp"

namespace uwscan::mapping::test {
namespace {

std::vector<FrameRecord> ReadAll(FrameReadAhead& frames) {
  std::vector<FrameRecord> all;
  while (std::optional<FrameRecord> frame = frames.Next()) all.push_back(std::move(*frame));
  return all;
}

// Some frames of the test logs carry images: a read-ahead of a few bytes holds one at a time.
TEST_F(DiveLogTest, ReadAheadHandsOverEveryFrameInOrder) {
  const fs::path path = WriteLog("dive.uwlog", 40, 25);
  const DiveLogReader reader(path);
  for (const std::size_t max_bytes : {std::size_t{1}, std::size_t{32} << 20}) {
    FrameReadAhead frames(reader, max_bytes);
    const std::vector<FrameRecord> all = ReadAll(frames);
    ASSERT_EQ(all.size(), 40u);
    for (std::int64_t i = 0; i < 40; ++i) ExpectSameFrame(TestFrame(i, 25), all[i]);
    EXPECT_FALSE(frames.Next());  // and stays at the end
  }
}

// A damaged row stops the reading where ForEachFrame stops: after the frames before it, with
// the reader's own message.
TEST_F(DiveLogTest, ReadAheadRaisesADamagedRowAfterTheFramesBeforeIt) {
  const fs::path path = WriteLog("damaged.uwlog", 12, 6);
  RawExec(path, "UPDATE frames SET peaks_px = x'0102' WHERE frame_index = 7");
  const DiveLogReader reader(path);
  FrameReadAhead frames(reader);
  for (std::int64_t i = 0; i < 7; ++i) {
    const std::optional<FrameRecord> frame = frames.Next();
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->index, i);
  }
  const std::string message = MessageOf([&] { frames.Next(); });
  EXPECT_NE(message.find("frame 7"), std::string::npos) << message;
  EXPECT_NE(message.find("peaks_px"), std::string::npos) << message;
  EXPECT_NE(message.find(path.string()), std::string::npos) << message;
}

// A consumer that stops early (an error of its own) leaves at once; the log is usable again.
TEST_F(DiveLogTest, ReadAheadStopsWhenItsConsumerLeaves) {
  const fs::path path = WriteLog("dive.uwlog", 200, 50);
  const DiveLogReader reader(path);
  {
    FrameReadAhead frames(reader, 1);
    ASSERT_TRUE(frames.Next());
  }
  EXPECT_EQ(reader.ReadFrame(199).index, 199);
}

}  // namespace
}  // namespace uwscan::mapping::test
