// The live view from other threads: budget and decay, and a dive log followed while it is
// written.
#include "viewer/render/live_view.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <thread>

#include "mapping/log/dive_log.hpp"
#include "mapping/log/dive_simulation.hpp"
#include "mapping/reconstruction/reconstruction.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"
#include "viewer/plots/png_image.hpp"
#include "viewer/render/dive_log_follower.hpp"

namespace uwscan::viewer {
namespace {

namespace fs = std::filesystem;

fs::path TempPath(const std::string& name) {
  return fs::temp_directory_path() /
         ("uwscan_live_view_test_" + std::to_string(::getpid()) + "_" + name);
}

LiveCloud Cloud(double time_s, int n) {
  LiveCloud cloud;
  cloud.time_s = time_s;
  for (int i = 0; i < n; ++i) cloud.points_W.emplace_back(0.01 * i, time_s, -1.0);
  return cloud;
}

TEST(LiveView, ProducersOnTwoThreadsStayWithinTheBudget) {
  LiveViewOptions options;
  options.point_budget = 10'000;
  LiveView view(options);
  auto produce = [&view](int first) {
    for (int k = 0; k < 50; ++k) view.Push(Cloud(first + k, 1000));
  };
  std::thread a(produce, 0), b(produce, 100);
  a.join();
  b.join();
  const LiveViewStats s = view.stats();
  EXPECT_EQ(s.clouds_received, 100);
  EXPECT_EQ(s.points_received, 100'000);
  EXPECT_LE(s.points_held, 10'000u);
  EXPECT_EQ(s.clouds_dropped, 90);
}

TEST(LiveView, CloudsOlderThanTheDecayTimeAreDropped) {
  LiveViewOptions options;
  options.decay_s = 5.0;
  LiveView view(options);
  for (int t = 0; t <= 20; ++t) view.Push(Cloud(t, 10));
  // Clouds at 15..20 s are within 5 s of the newest.
  EXPECT_EQ(view.stats().points_held, 60u);
}

TEST(LiveView, PerPointArraysOfTheWrongSizeAreRefused) {
  LiveView view(LiveViewOptions{});
  LiveCloud cloud = Cloud(0.0, 10);
  cloud.error_m.resize(3);
  EXPECT_THROW(view.Push(cloud), Error);
}

// A simulated dive copied frame by frame into a new log by a writer that starts after the view
// and the follower: every frame must reach the view, as Reconstruct would place it.
TEST(DiveLogFollower, PicksUpFramesAppendedAfterItStarted) {
  const scanner::sim::Scene scene =
      scanner::sim::LoadScene(fs::path(UWSCAN_SOURCE_DIR_FOR_TESTS) / "data/scenes/default.yaml");
  const scanner::sim::Simulator simulator(scene);
  const fs::path source = TempPath("source.db"), growing = TempPath("growing.db"),
                 png = TempPath("live.png");
  fs::remove(source);
  fs::remove(growing);
  mapping::SimulateDive(simulator, "", source, mapping::DiveSimulationOptions{});
  const mapping::DiveLogReader reader(source);
  const std::int64_t frames = reader.frame_count();
  // The tables are kept in a folder of the test's own, so the follower finds them made.
  mapping::ReconstructionOptions reconstruction;
  reconstruction.table_cache = TempPath("tables");
  const std::size_t expected_points = mapping::Reconstruct(reader, reconstruction).points.size();

  LiveViewOptions options;
  options.offscreen = true;
  options.render.width_px = 320;
  options.render.height_px = 240;
  options.render.colour = ColourMode::kError;
  options.refresh_s = 0.05;
  LiveView view(options);
  view.SetFinalScreenshot(png);
  FollowOptions follow;
  follow.reconstruction = reconstruction;
  follow.poll_s = 0.02;
  follow.stop_after_frames = frames;
  follow.timeout_s = 60.0;
  DiveLogFollower follower(growing, follow, view);

  std::atomic<std::int64_t> seen_when_half_written{-1};
  std::thread writer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the follower waits for the file
    mapping::DiveLogWriter out(growing, reader.header());
    out.SetVehicleMount(*reader.vehicle_mount());
    for (const mapping::NavigationRecord& nav : reader.ReadNavigation()) out.AppendNavigation(nav);
    for (std::int64_t i = 0; i < frames; ++i) {
      const std::optional<mapping::GroundTruthRecord> truth = reader.ReadGroundTruth(i);
      out.AppendFrame(reader.ReadFrame(i), truth ? &*truth : nullptr);
      if (i == frames / 2) {
        // Paused half-way: the view must get the frames written so far without the rest.
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
        while (follower.status().frames <= i && std::chrono::steady_clock::now() < deadline) {
          std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        seen_when_half_written = follower.status().frames;
      }
    }
  });
  view.Run("test");
  writer.join();

  const FollowStatus status = follower.status();
  EXPECT_TRUE(status.error.empty()) << status.error;
  EXPECT_EQ(status.frames, frames);
  EXPECT_EQ(static_cast<std::size_t>(status.points), expected_points);
  // Half-way, the view already had the first half: it follows, it does not wait for the end.
  EXPECT_EQ(seen_when_half_written.load(), frames / 2 + 1);
  const LiveViewStats stats = view.stats();
  EXPECT_EQ(stats.points_held, expected_points);
  EXPECT_GE(stats.redraws, 1);
  EXPECT_EQ(stats.poses_received, 2 * frames);  // navigation and truth per frame

  // The final picture shows the dive: many pixels differ from the background.
  const RgbImage image = ReadPng(png);
  int drawn = 0;
  for (int row = 40; row < image.height_px; ++row) {
    for (int col = 0; col < image.width_px; ++col)
      drawn += !(image.At(col, row) == options.render.background);
  }
  EXPECT_GT(drawn, 2000);
  for (const char* suffix : {"", "-wal", "-shm"}) {  // SQLite's side files too
    fs::remove(source.string() + suffix);
    fs::remove(growing.string() + suffix);
  }
  fs::remove(png);
  fs::remove_all(reconstruction.table_cache);
}

TEST(DiveLogFollower, MissingLogTimesOutWithAnErrorNamingIt) {
  LiveViewOptions options;
  options.offscreen = true;
  options.render.width_px = 64;
  options.render.height_px = 64;
  LiveView view(options);
  FollowOptions follow;
  follow.poll_s = 0.05;
  follow.timeout_s = 0.3;
  const fs::path missing = TempPath("never.db");
  DiveLogFollower follower(missing, follow, view);
  view.Run("test");
  const FollowStatus status = follower.status();
  EXPECT_TRUE(status.finished);
  EXPECT_NE(status.error.find(missing.string()), std::string::npos) << status.error;
}

}  // namespace
}  // namespace uwscan::viewer
