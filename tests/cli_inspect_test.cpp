// `uwscan inspect` end to end, as a user runs it against `uwscan fake-camera`: every frame
// logged, the live map on the scene, frames received = mapped + skipped, latency reported,
// Ctrl-C, a wrong address, and the live view's last picture. CTest runs every test in a
// private network namespace with only `lo` up (cmake/run_in_netns.sh).
#include <gtest/gtest.h>

#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "mapping/log/dive_log.hpp"
#include "tests/cli_camera_support.hpp"
#include "tests/cli_run.hpp"
#include "viewer/plots/png_image.hpp"

namespace {

namespace fs = std::filesystem;
using namespace uwscan::test;

fs::path TempPath(const std::string& name) { return ScratchPath(name); }
std::unique_ptr<Background> StartFakeCamera(const std::vector<std::string>& args,
                                            const std::string& name) {
  return StartFakeCameraLogged(args, TempPath(name + ".log"));
}

void ExpectEveryFrameAccountedFor(const nlohmann::json& j, const fs::path& log) {
  const std::int64_t received = j["frames_received"].get<std::int64_t>();
  EXPECT_EQ(j["frames_logged"].get<std::int64_t>(), received);
  EXPECT_EQ(uwscan::mapping::DiveLogReader(log).frame_count(), received);
  EXPECT_EQ(j["frames_mapped"].get<std::int64_t>() + j["frames_skipped"].get<std::int64_t>() +
                j["frames_out_of_order"].get<std::int64_t>(),
            received);
  EXPECT_GT(j["frames_mapped"].get<std::int64_t>(), 0);
}

// Every frame the camera sent and inspect never logged is counted (CounterGapsOf). A shared
// machine can starve the receiver long enough for Aravis to drop a few (a CI run lost 3 of 606);
// more than 1 % is a receiver that does not keep up with 200 frames/s.
void ExpectLossCountedAndSmall(const nlohmann::json& j, const fs::path& log) {
  const CounterGaps gaps = CounterGapsOf(log);
  ASSERT_GT(gaps.logged, 0);
  ASSERT_TRUE(gaps.in_order);
  const std::int64_t lost = j["lost_frames"].get<std::int64_t>();
  std::printf("profile mode: %lld of %lld frames lost (%lld incomplete)\n",
              static_cast<long long>(lost), static_cast<long long>(gaps.logged),
              static_cast<long long>(j["incomplete_frames"].get<std::int64_t>()));
  EXPECT_EQ(lost, gaps.missing);
  EXPECT_LE(lost, gaps.logged / 100);
}

// Profile mode: 3 sweeps of the default scene (a fixed scanner, world = camera frame). Every
// frame is in the log; the map lies on the cloud `simulate` + `reconstruct` make of the scene
// (a map point is a voxel's centroid: within the voxel's diagonal of a point it averages).
TEST(CliInspect, ProfileModeLogsEveryFrameAndMapsTheScene) {
  const std::string scene = SourcePath("data/scenes/default.yaml");
  const fs::path simulated = TempPath("sim.db"), cloud = TempPath("sim.ply");
  ASSERT_EQ(RunUwscan("simulate " + scene + " -o " + simulated.string()).exit_code, 0);
  ASSERT_EQ(RunUwscan("reconstruct " + simulated.string() + " --scanner-frame --ascii -o " +
                      cloud.string())
                .exit_code,
            0);
  auto camera = StartFakeCamera({"fake-camera", scene}, "profile_camera");
  const fs::path log = TempPath("profile.db"), json = TempPath("profile.json"),
                 map = TempPath("map.ply");
  const double voxel_m = 0.002;
  const CommandRun run =
      RunUwscan("inspect --camera 127.0.0.1 --scene " + scene + " --log " + log.string() +
                " --frames 603 --voxel " + std::to_string(voxel_m) + " --ascii -o " + map.string() +
                " --json " + json.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json j = ReadJson(json);
  EXPECT_EQ(j["frames_received"].get<std::int64_t>(), 603) << run.output;
  ExpectLossCountedAndSmall(j, log);
  ExpectEveryFrameAccountedFor(j, log);
  // The fake camera's clock is the host's: both latencies are known, and short.
  const nlohmann::json& latency = j["latency_s"];
  ASSERT_TRUE(latency.contains("capture_to_map")) << latency.dump();
  EXPECT_GT(latency["receive_to_map"]["median_s"].get<double>(), 0.0);
  EXPECT_LT(latency["capture_to_map"]["median_s"].get<double>(), 0.5);
  EXPECT_NE(run.output.find("skipped"), std::string::npos) << run.output;

  const std::vector<Eigen::Vector3d> truth = ReadAsciiPly(cloud);
  const std::vector<Eigen::Vector3d> mapped = ReadAsciiPly(map);
  ASSERT_GT(truth.size(), 100000u);
  ASSERT_GT(mapped.size(), 10000u);
  EXPECT_EQ(mapped.size(), j["map_points"].get<std::size_t>());
  const double worst_m = MaxNearestDistance(mapped, truth, 0.005);
  std::printf("profile mode: %zu map points, farthest %.3f mm from the simulated cloud\n",
              mapped.size(), worst_m * 1e3);
  EXPECT_LT(worst_m, std::sqrt(3.0) * voxel_m + 1e-4);
}

// Image mode: the host's detector finds the stripes in 2048x1088 frames; the map lies on the
// scene's simulated cloud within the voxel and the detector's accuracy.
TEST(CliInspect, ImageModeDetectsOnTheHostAndMapsTheScene) {
  const std::string scene = SourcePath("data/scenes/camera_image.yaml");
  const fs::path simulated = TempPath("image_sim.db"), cloud = TempPath("image_sim.ply");
  ASSERT_EQ(RunUwscan("simulate " + scene + " -o " + simulated.string()).exit_code, 0);
  ASSERT_EQ(RunUwscan("reconstruct " + simulated.string() + " --scanner-frame --ascii -o " +
                      cloud.string())
                .exit_code,
            0);
  auto camera =
      StartFakeCamera({"fake-camera", scene, "--mode", "image", "--fps", "60"}, "image_camera");
  const fs::path log = TempPath("image.db"), json = TempPath("image.json"),
                 map = TempPath("image_map.ply");
  const CommandRun run = RunUwscan("inspect --camera 127.0.0.1 --scene " + scene + " --log " +
                                   log.string() + " --frames 63 --voxel 0.002 --ascii -o " +
                                   map.string() + " --json " + json.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json j = ReadJson(json);
  EXPECT_EQ(j["frames_received"].get<std::int64_t>(), 63);
  ExpectEveryFrameAccountedFor(j, log);
  const std::vector<Eigen::Vector3d> mapped = ReadAsciiPly(map);
  ASSERT_GT(mapped.size(), 1000u);
  const double worst_m = MaxNearestDistance(mapped, ReadAsciiPly(cloud), 0.005);
  std::printf("image mode: %zu map points, farthest %.3f mm from the simulated cloud\n",
              mapped.size(), worst_m * 1e3);
  EXPECT_LT(worst_m, std::sqrt(3.0) * 0.002 + 0.5e-3);
}

// Ctrl-C mid-stream: inspect stops, maps what it has, and leaves a closed, readable log with
// every frame it received.
TEST(CliInspect, CtrlCStopsCleanlyWithAReadableLog) {
  const std::string scene = SourcePath("data/scenes/default.yaml");
  auto camera = StartFakeCamera({"fake-camera", scene}, "ctrlc_camera");
  const fs::path log = TempPath("ctrlc.db"), json = TempPath("ctrlc.json");
  Background inspect({"inspect", "--camera", "127.0.0.1", "--scene", scene, "--log", log.string(),
                      "--json", json.string()},
                     TempPath("ctrlc_inspect.log"));
  ASSERT_TRUE(inspect.WaitFor("profile mode", 20.0)) << inspect.Output();
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  inspect.Signal(SIGINT);
  EXPECT_EQ(inspect.Wait(), 0) << inspect.Output();
  EXPECT_NE(inspect.Output().find("stopped by SIGINT"), std::string::npos) << inspect.Output();
  EXPECT_FALSE(fs::exists(log.string() + "-wal")) << "the log was closed";
  const nlohmann::json j = ReadJson(json);
  EXPECT_TRUE(j["stopped_by_signal"].get<bool>());
  EXPECT_GT(j["frames_received"].get<std::int64_t>(), 200);
  ExpectEveryFrameAccountedFor(j, log);
  const uwscan::mapping::DiveLogReader reader(log);
  EXPECT_GT(reader.ReadFrame(reader.frame_count() - 1).peaks_px.size(), 500u);
}

TEST(CliInspect, AWrongAddressFailsClearlyWithinSeconds) {
  const Clock::time_point start = Clock::now();
  const CommandRun run =
      RunUwscan("inspect --camera 127.0.0.2 --log " + TempPath("none.db").string() + " --scene " +
                SourcePath("data/scenes/default.yaml"));
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("camera 127.0.0.2: no GigE Vision camera answers there"),
            std::string::npos)
      << run.output;
  EXPECT_LT(seconds, 5.0);
  EXPECT_FALSE(fs::exists(TempPath("none.db")));
}

TEST(CliInspect, BadOptionsFailBeforeTheCameraIsOpened) {
  const std::string scene = SourcePath("data/scenes/default.yaml");
  const CommandRun both =
      RunUwscan("inspect --camera 127.0.0.1 --scene " + scene + " --frames 3 --seconds 1");
  EXPECT_EQ(both.exit_code, 1);
  EXPECT_NE(both.output.find("--frames and --seconds"), std::string::npos) << both.output;
  const CommandRun neither = RunUwscan("inspect --camera 127.0.0.1");
  EXPECT_EQ(neither.exit_code, 1);
  EXPECT_NE(neither.output.find("give --scene"), std::string::npos) << neither.output;
  const CommandRun xyz = RunUwscan("inspect --camera 127.0.0.1 --scene " + scene + " -o " +
                                   TempPath("m.xyz").string());
  EXPECT_EQ(xyz.exit_code, 1);
  EXPECT_NE(xyz.output.find("a point cloud is written as .ply or .pcd"), std::string::npos)
      << xyz.output;
  const CommandRun shot = RunUwscan("inspect --camera 127.0.0.1 --scene " + scene +
                                    " --screenshot " + TempPath("never.png").string());
  EXPECT_EQ(shot.exit_code, 1);
  EXPECT_NE(shot.output.find("--screenshot: say when"), std::string::npos) << shot.output;
}

// --view with --screenshot: the live view renders offscreen (under Xvfb) while frames come in
// and writes its last picture when the run ends.
TEST(CliInspect, TheLiveViewWritesItsLastPicture) {
  const std::string scene = SourcePath("data/scenes/default.yaml");
  auto camera = StartFakeCamera({"fake-camera", scene}, "view_camera");
  const fs::path png = TempPath("live.png"), json = TempPath("view.json");
  const CommandRun run =
      RunCommand(SourcePath("cmake/run_with_display.sh") + " " + UWSCAN_BIN +
                 " inspect --camera 127.0.0.1 --scene " + scene + " --frames 402 --screenshot " +
                 png.string() + " --json " + json.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find(png.string() + ": written"), std::string::npos) << run.output;
  ASSERT_TRUE(fs::exists(png));
  const std::string bytes = ReadFile(png);
  ASSERT_GT(bytes.size(), 24u);
  EXPECT_EQ(bytes.compare(1, 3, "PNG"), 0);
  EXPECT_GT(bytes.size(), 20000u) << "a picture of the scene, not an empty window";
  EXPECT_GT(ReadJson(json)["frames_mapped"].get<std::int64_t>(), 0);
}

// --reference colours the live map by its deviation from a design model: against the scene as
// built the map is grey (within the live threshold); against a design whose seabed lies 1 cm
// deeper (NED: further from the camera), the seabed in the map is 1 cm in front of it: gained, red.
TEST(CliInspect, TheLiveViewColoursTheMapByItsDeviationFromAReference) {
  const std::string scene = SourcePath("data/scenes/default.yaml");
  std::string deeper = ReadFile(scene);
  const std::string seabed = "translation_m: [0, 0, 1.3]";
  ASSERT_NE(deeper.find(seabed), std::string::npos);
  deeper.replace(deeper.find(seabed), seabed.size(), "translation_m: [0, 0, 1.31]");
  const std::string scanners = "../scanners/";
  ASSERT_NE(deeper.find(scanners), std::string::npos);
  deeper.replace(deeper.find(scanners), scanners.size(), SourcePath("data/scanners/"));
  const fs::path deeper_scene = TempPath("deeper.yaml");
  { std::ofstream(deeper_scene) << deeper; }
  auto camera = StartFakeCamera({"fake-camera", scene}, "reference_camera");
  int red[2] = {0, 0};
  const fs::path designs[2] = {TempPath("design.ply"), TempPath("deeper_design.ply")};
  const std::string scenes[2] = {scene, deeper_scene.string()};
  for (int k = 0; k < 2; ++k) {
    const CommandRun design =
        RunUwscan("simulate " + scenes[k] + " -o " + TempPath("design.db").string() +
                  " --force --design " + designs[k].string());
    ASSERT_EQ(design.exit_code, 0) << design.output;
    const fs::path png = TempPath("reference.png");
    const CommandRun run =
        RunCommand(SourcePath("cmake/run_with_display.sh") + " " + UWSCAN_BIN +
                   " inspect --camera 127.0.0.1 --scene " + scene + " --frames 402 --screenshot " +
                   png.string() + " --reference " + designs[k].string());
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const uwscan::viewer::RgbImage image = uwscan::viewer::ReadPng(png);
    for (int row = 0; row < image.height_px; ++row) {
      for (int column = 0; column < image.width_px * 4 / 5; ++column) {  // the colour bar aside
        const uwscan::viewer::Rgb c = image.At(column, row);
        red[k] += c.r > 120 && c.r > c.b + 60 && c.r > c.g + 60;
      }
    }
  }
  std::printf("red pixels: %d against the scene as built, %d against a seabed 1 cm deeper\n",
              red[0], red[1]);
  EXPECT_LT(red[0], 500) << "the scene as built: grey";
  EXPECT_GT(red[1], 20 * std::max(red[0], 100)) << "a seabed 1 cm deeper: the map's is gained";
}

}  // namespace
