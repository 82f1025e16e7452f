// The camera commands end to end, as a user runs them: `uwscan fake-camera` serving a scene
// over GigE Vision, `uwscan acquire` recording it. CTest runs every test in a private network
// namespace with only `lo` up (cmake/run_in_netns.sh), so no packet leaves the machine.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "mapping/log/dive_log.hpp"
#include "tests/cli_camera_support.hpp"
#include "tests/cli_run.hpp"

namespace {

namespace fs = std::filesystem;
using namespace uwscan::test;

fs::path TempPath(const std::string& name) { return ScratchPath(name); }
std::unique_ptr<Background> StartFakeCamera(const std::vector<std::string>& args,
                                            const std::string& name) {
  return StartFakeCameraLogged(args, TempPath(name + ".log"));
}

using PeaksByLine = std::map<int, std::vector<double>>;  // row -> sorted u positions

PeaksByLine ByRow(const std::vector<Eigen::Vector2d>& peaks) {
  PeaksByLine rows;
  for (const Eigen::Vector2d& p : peaks)
    rows[static_cast<int>(std::lround(p.y()))].push_back(p.x());
  for (auto& [row, us] : rows) std::sort(us.begin(), us.end());
  return rows;
}

// The simulated log's frames by mirror command (one sweep).
std::map<int, uwscan::mapping::FrameRecord> FramesByCommand(const fs::path& log) {
  std::map<int, uwscan::mapping::FrameRecord> frames;
  uwscan::mapping::DiveLogReader reader(log);
  reader.ForEachFrame([&](const uwscan::mapping::FrameRecord& f,
                          const uwscan::mapping::GroundTruthRecord*) { frames[f.command] = f; },
                      false);
  return frames;
}

// Profile mode over both of Aravis's receive paths: a whole dive, each frame's peaks are the
// simulator's exact peaks within the fixed-point step (1/32 px for 2048-px rows).
TEST(CliAcquisition, ProfileModeCarriesTheExactPeaksOverBothReceivePaths) {
  const std::string scene = SourcePath("data/scenes/default.yaml");
  const fs::path truth = TempPath("truth.db");
  ASSERT_EQ(RunUwscan("simulate " + scene + " -o " + truth.string()).exit_code, 0);
  const auto expected = FramesByCommand(truth);
  auto camera = StartFakeCamera({"fake-camera", scene, "--mode", "profile"}, "profile_camera");
  for (const std::string path : {"packet", "udp"}) {
    const fs::path log = TempPath("profile_" + path + ".db");
    const fs::path json = TempPath("profile_" + path + ".json");
    const CommandRun run =
        RunUwscan("acquire --camera 127.0.0.1 -o " + log.string() + " --frames 201 --scene " +
                  scene + " --receive " + path + " --json " + json.string());
    ASSERT_EQ(run.exit_code, 0) << run.output;
    // A loaded machine can starve the receiver into dropping a frame or two; not more than 1 %.
    EXPECT_LE(ReadJson(json)["lost_frames"].get<int>(), 2) << path;
    uwscan::mapping::DiveLogReader reader(log);
    ASSERT_EQ(reader.frame_count(), 201) << path;
    std::set<int> commands;
    const double step = 1.0 / 32.0;
    reader.ForEachFrame(
        [&](const uwscan::mapping::FrameRecord& f, const uwscan::mapping::GroundTruthRecord*) {
          commands.insert(f.command);
          ASSERT_TRUE(expected.count(f.command)) << f.command;
          const uwscan::mapping::FrameRecord& e = expected.at(f.command);
          EXPECT_NEAR(f.time_s, e.time_s + f.sweep * 201 / 339.0, 1e-6);
          const PeaksByLine got = ByRow(f.peaks_px);
          const PeaksByLine want = ByRow(e.peaks_px);
          ASSERT_EQ(got.size(), want.size()) << "command " << f.command;
          for (const auto& [row, us] : want) {
            ASSERT_TRUE(got.count(row)) << row;
            ASSERT_EQ(got.at(row).size(), us.size()) << row;
            for (std::size_t k = 0; k < us.size(); ++k)
              EXPECT_LE(std::abs(got.at(row)[k] - us[k]), step / 2 + 1e-9);
          }
        },
        false);
    EXPECT_EQ(commands.size(), 201u) << "every mirror step once";
  }
  camera->Signal(SIGINT);
  EXPECT_EQ(camera->Wait(), 0);
  EXPECT_NE(camera->Output().find("stopped"), std::string::npos) << camera->Output();
}

// Image mode: 2048 x 1088 Mono8 frames rendered by the simulator, searched by the host's stripe
// detector, against the exact peaks of the same scene without the image stage.
TEST(CliAcquisition, ImageModePeaksMatchTheExactPeaksWithinTheDetectorsAccuracy) {
  const std::string scene = SourcePath("data/scenes/camera_image.yaml");
  std::string exact_text;
  {
    std::istringstream lines(ReadFile(scene));
    std::string line;
    while (std::getline(lines, line)) {
      if (line.rfind("  image:", 0) == 0) continue;
      const std::size_t at = line.find("../scanners/");
      if (at != std::string::npos) line.replace(at, 2, SourcePath("data"));
      exact_text += line + "\n";
    }
  }
  const fs::path exact_scene = TempPath("exact.yaml");
  std::ofstream(exact_scene) << exact_text;
  const fs::path truth = TempPath("image_truth.db");
  const CommandRun sim = RunUwscan("simulate " + exact_scene.string() + " -o " + truth.string());
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const auto expected = FramesByCommand(truth);
  auto camera =
      StartFakeCamera({"fake-camera", scene, "--mode", "image", "--fps", "60"}, "image_camera");
  const fs::path log = TempPath("image.db");
  const CommandRun run = RunUwscan("acquire --camera 127.0.0.1 -o " + log.string() +
                                   " --frames 21 --images --scene " + scene);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  uwscan::mapping::DiveLogReader reader(log);
  ASSERT_EQ(reader.frame_count(), 21);
  std::vector<double> errors;
  std::int64_t expected_peaks = 0;
  reader.ForEachFrame(
      [&](const uwscan::mapping::FrameRecord& f, const uwscan::mapping::GroundTruthRecord*) {
        ASSERT_TRUE(f.image) << "--images keeps the frame";
        EXPECT_EQ(f.image->width_px, 2048);
        EXPECT_EQ(f.image->height_px, 1088);
        const PeaksByLine got = ByRow(f.peaks_px);
        const PeaksByLine want = ByRow(expected.at(f.command).peaks_px);
        for (const auto& [row, us] : want) {
          expected_peaks += static_cast<std::int64_t>(us.size());
          if (us.size() != 1 || !got.count(row) || got.at(row).size() != 1) continue;
          errors.push_back(std::abs(got.at(row)[0] - us[0]));
        }
      },
      false);
  ASSERT_GT(errors.size(), 0.9 * expected_peaks) << "rows with one exact and one detected peak";
  std::sort(errors.begin(), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.05) << "median error, px";
  EXPECT_LT(errors[errors.size() * 99 / 100], 0.3) << "99th percentile, px";
}

// --loss 0.01: the frames the camera withheld are counted exactly. The truth comes from the
// frames themselves: each carries the camera's frame counter's mirror command and sweep.
TEST(CliAcquisition, LostFramesAreCountedExactly) {
  const std::string scene = SourcePath("data/scenes/default.yaml");
  auto camera = StartFakeCamera(
      {"fake-camera", scene, "--fps", "1000", "--loss", "0.01", "--seed", "5"}, "loss_camera");
  const fs::path log = TempPath("loss.db");
  const fs::path json = TempPath("loss.json");
  const CommandRun run = RunUwscan("acquire --camera 127.0.0.1 -o " + log.string() +
                                   " --frames 2000 --scene " + scene + " --json " + json.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const CounterGaps gaps = CounterGapsOf(log);
  ASSERT_EQ(gaps.logged, 2000);
  ASSERT_TRUE(gaps.in_order);
  EXPECT_GT(gaps.missing, 5);  // about 1 %
  EXPECT_LT(gaps.missing, 60);
  const nlohmann::json j = ReadJson(json);
  EXPECT_EQ(j["lost_frames"].get<std::int64_t>(), gaps.missing);
  // A receiver starved of the CPU may also miss packets of a frame the camera sent: that frame
  // is not logged, and it is counted among the lost, as incomplete (none here when idle).
  EXPECT_GE(j["incomplete_frames"].get<std::int64_t>(), 0);
  EXPECT_LE(j["incomplete_frames"].get<std::int64_t>(), j["lost_frames"].get<std::int64_t>());
}

// The camera dies mid-stream and comes back: every frame received is in the log, the gap is
// reported, and frames are recorded again once it answers.
TEST(CliAcquisition, ACameraThatDiesIsReopenedAndTheGapReported) {
  const std::string scene = SourcePath("data/scenes/default.yaml");
  auto camera = StartFakeCamera({"fake-camera", scene}, "dying_camera");
  const fs::path log = TempPath("gap.db");
  const fs::path json = TempPath("gap.json");
  Background acquire({"acquire", "--camera", "127.0.0.1", "-o", log.string(), "--seconds", "5",
                      "--scene", scene, "--watchdog-s", "0.5", "--json", json.string()},
                     TempPath("gap_acquire.log"));
  ASSERT_TRUE(acquire.WaitFor("profile mode", 20.0)) << acquire.Output();
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  camera->Signal(SIGKILL);
  camera->Wait();
  const std::int64_t before = uwscan::mapping::DiveLogReader(log).frame_count();
  EXPECT_GT(before, 100);
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  auto again = StartFakeCamera({"fake-camera", scene}, "back_camera");
  EXPECT_EQ(acquire.Wait(), 0) << acquire.Output();
  const nlohmann::json j = ReadJson(json);
  ASSERT_EQ(j["gaps"].size(), 1u) << acquire.Output();
  const double silent = j["gaps"][0]["silent_after_s"].get<double>();
  const double resumed = j["gaps"][0]["resumed_at_s"].get<double>();
  EXPECT_GT(silent, 0.5);  // frames for about a second, then nothing
  EXPECT_GT(resumed, silent + 0.9) << "the camera was away for a second at least";
  EXPECT_NE(acquire.Output().find("camera silent after"), std::string::npos) << acquire.Output();
  const uwscan::mapping::DiveLogReader reader(log);
  EXPECT_EQ(reader.frame_count(), j["frames"].get<std::int64_t>());
  EXPECT_GT(reader.frame_count(), before + 100) << "frames after the camera came back";
}

// Ctrl-C mid-stream: acquire stops, writes what it received and leaves a closed, readable log.
TEST(CliAcquisition, CtrlCLeavesAClosedReadableLog) {
  const std::string scene = SourcePath("data/scenes/default.yaml");
  auto camera = StartFakeCamera({"fake-camera", scene}, "ctrlc_camera");
  const fs::path log = TempPath("ctrlc.db");
  Background acquire({"acquire", "--camera", "127.0.0.1", "-o", log.string(), "--scene", scene},
                     TempPath("ctrlc_acquire.log"));
  ASSERT_TRUE(acquire.WaitFor("profile mode", 20.0)) << acquire.Output();
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  acquire.Signal(SIGINT);
  EXPECT_EQ(acquire.Wait(), 0) << acquire.Output();
  EXPECT_NE(acquire.Output().find("stopped by SIGINT"), std::string::npos) << acquire.Output();
  EXPECT_FALSE(fs::exists(log.string() + "-wal")) << "the log was closed";
  const uwscan::mapping::DiveLogReader reader(log);
  EXPECT_GT(reader.frame_count(), 100);
  const uwscan::mapping::FrameRecord last = reader.ReadFrame(reader.frame_count() - 1);
  EXPECT_GT(last.peaks_px.size(), 500u);
}

// SIGKILL mid-stream (no chance to close anything): the log reads, checks clean, and holds the
// frames committed before the kill, each whole. The killed acquire still holds the camera's
// control until the camera's heartbeat runs out: the next acquire waits for it and takes over,
// while an acquire beside a live one is refused, saying why.
TEST(CliAcquisition, KilledMidStreamTheLogHoldsEveryCommittedFrame) {
  const std::string scene = SourcePath("data/scenes/default.yaml");
  auto camera = StartFakeCamera({"fake-camera", scene}, "killed_camera");
  {
    Background holder({"acquire", "--camera", "127.0.0.1", "-o", TempPath("holder.db").string(),
                       "--scene", scene},
                      TempPath("holder_acquire.log"));
    ASSERT_TRUE(holder.WaitFor("profile mode", 20.0)) << holder.Output();
    const CommandRun second = RunUwscan("acquire --camera 127.0.0.1 --frames 10 -o " +
                                        TempPath("second.db").string() + " --scene " + scene);
    EXPECT_NE(second.exit_code, 0);
    EXPECT_NE(second.output.find("another program controls the camera"), std::string::npos)
        << second.output;
    holder.Signal(SIGINT);  // a clean stop hands the camera back at once
    EXPECT_EQ(holder.Wait(), 0) << holder.Output();
  }
  for (const int after_ms : {300, 1100}) {
    const fs::path log = TempPath("killed_" + std::to_string(after_ms) + ".db");
    Background acquire({"acquire", "--camera", "127.0.0.1", "-o", log.string(), "--scene", scene},
                       TempPath("killed_acquire.log"));
    ASSERT_TRUE(acquire.WaitFor("profile mode", 20.0)) << acquire.Output();
    std::this_thread::sleep_for(std::chrono::milliseconds(after_ms));
    acquire.Signal(SIGKILL);
    acquire.Wait();
    const CommandRun check = RunUwscan("log check " + log.string());
    EXPECT_EQ(check.exit_code, 0) << check.output;
    const uwscan::mapping::DiveLogReader reader(log);
    ASSERT_GT(reader.frame_count(), 0) << "killed after " << after_ms << " ms:\n"
                                       << acquire.Output();
    for (std::int64_t i = 0; i + 1 < reader.frame_count(); ++i)
      reader.ReadFrame(i);  // each checks its checksums
    EXPECT_GT(reader.ReadFrame(reader.frame_count() - 1).peaks_px.size(), 500u);
  }
}

TEST(CliAcquisition, AWrongAddressFailsClearlyWithinSeconds) {
  const Clock::time_point start = Clock::now();
  const CommandRun run = RunUwscan("acquire --camera 127.0.0.2 -o " + TempPath("none.db").string() +
                                   " --scene " + SourcePath("data/scenes/default.yaml"));
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("camera 127.0.0.2: no GigE Vision camera answers there"),
            std::string::npos)
      << run.output;
  EXPECT_LT(seconds, 5.0);
  EXPECT_FALSE(fs::exists(TempPath("none.db")));
}

// The scene acquired through the fake camera reconstructs to the cloud `simulate` +
// `reconstruct` make of it: the same number of points, each within 0.1 mm of its counterpart
// (the profile's 1/32 px step).
TEST(CliAcquisition, AnAcquiredSceneReconstructsToTheSimulatedCloud) {
  const std::string scene = SourcePath("data/scenes/default.yaml");
  const fs::path simulated = TempPath("recon_sim.db");
  ASSERT_EQ(RunUwscan("simulate " + scene + " -o " + simulated.string()).exit_code, 0);
  auto camera = StartFakeCamera({"fake-camera", scene}, "recon_camera");
  const fs::path acquired = TempPath("recon_acq.db");
  const CommandRun run = RunUwscan("acquire --camera 127.0.0.1 -o " + acquired.string() +
                                   " --frames 201 --scene " + scene);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const fs::path cloud_sim = TempPath("sim.ply");
  const fs::path cloud_acq = TempPath("acq.ply");
  ASSERT_EQ(RunUwscan("reconstruct " + simulated.string() + " --scanner-frame --ascii -o " +
                      cloud_sim.string())
                .exit_code,
            0);
  const CommandRun rec =
      RunUwscan("reconstruct " + acquired.string() + " --ascii -o " + cloud_acq.string());
  ASSERT_EQ(rec.exit_code, 0) << rec.output;
  const std::vector<Eigen::Vector3d> a = ReadAsciiPly(cloud_sim);
  const std::vector<Eigen::Vector3d> b = ReadAsciiPly(cloud_acq);
  ASSERT_GT(a.size(), 100000u);
  EXPECT_EQ(a.size(), b.size());
  EXPECT_LT(MaxNearestDistance(a, b), 1e-4);
  EXPECT_LT(MaxNearestDistance(b, a), 1e-4);
}

}  // namespace
