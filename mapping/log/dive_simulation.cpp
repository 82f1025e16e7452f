#include "mapping/log/dive_simulation.hpp"

#include <omp.h>

#include <chrono>
#include <vector>

#include "mapping/log/dive_log.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/common/parallel_tasks.hpp"

namespace uwscan::mapping {
namespace {

constexpr int kFramesPerThreadAndBlock = 4;

LogImage ToLogImage(const scanner::StripeFrame& frame) {
  LogImage image;
  image.width_px = frame.width_px;
  image.height_px = frame.height_px;
  if (frame.format == scanner::PixelFormat::kMono8) {
    image.format = LogPixelFormat::kMono8;
    image.bytes = frame.mono8;
  } else {
    image.format = LogPixelFormat::kMono16;
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(frame.mono16.data());
    image.bytes.assign(bytes, bytes + frame.mono16.size() * sizeof(std::uint16_t));
  }
  return image;
}

}  // namespace

void DiveSimulationOptions::Check() const {
  const OptionChecks check("DiveSimulationOptions");
  check.AtLeast("threads", threads, 0);
  check.InRange("navigation_rate_hz", navigation_rate_hz, 0.0, 1000.0, Interval::kOpenLow, "Hz");
}

DiveSimulationSummary SimulateDive(const scanner::sim::Simulator& simulator,
                                   const std::string& scene_yaml,
                                   const std::filesystem::path& log_path,
                                   const DiveSimulationOptions& options,
                                   const std::function<void(double)>& progress) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  const scanner::sim::Scene& scene = simulator.scene();

  DiveLogHeader header;
  header.scanner = simulator.scanner();
  header.scan_pattern = simulator.scan_pattern();
  header.scene_yaml = scene_yaml;
  header.producer = options.producer;
  // The navigation's noise as the scene made it: zero when it reports the truth.
  const scanner::sim::SimulationEffects::NavigationDrift& drift = scene.effects.navigation_drift;
  NavigationNoise noise;
  if (drift.on) {
    noise.position_walk_m_per_sqrt_s = drift.position_walk_m_per_sqrt_s;
    noise.heading_walk_rad_per_sqrt_s = drift.yaw_walk_rad_per_sqrt_s;
    noise.speed_scale_sigma = drift.speed_scale_sigma;
    noise.heading_bias_sigma_rad = drift.heading_bias_sigma_rad;
    noise.depth_sigma_m = drift.depth_sigma_m;
    noise.roll_pitch_sigma_rad = drift.roll_pitch_sigma_rad;
  }
  header.navigation_noise = noise;
  DiveLogWriter writer(log_path, header);
  writer.SetVehicleMount(scene.trajectory.T_V_C);

  DiveSimulationSummary summary;
  for (const scanner::sim::NavigationSample& nav :
       simulator.Navigation(options.navigation_rate_hz)) {
    writer.AppendNavigation(NavigationRecord{nav.time_s, nav.T_W_V});
    ++summary.navigation_records;
  }

  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  const std::int64_t total = simulator.frame_count();
  const std::int64_t block = static_cast<std::int64_t>(threads) * kFramesPerThreadAndBlock;
  std::vector<scanner::sim::SimulatedFrame> frames;
  for (std::int64_t first = 0; first < total; first += block) {
    const std::int64_t count = std::min(block, total - first);
    frames.assign(static_cast<size_t>(count), {});
    RunParallelTasks(count, threads, [&](std::ptrdiff_t k) {
      frames[static_cast<size_t>(k)] = simulator.Frame(first + k);
    });
    for (const scanner::sim::SimulatedFrame& f : frames) {
      FrameRecord record;
      record.time_s = f.time_s;
      record.command = f.command;
      record.sweep = f.sweep;
      record.peaks_px = f.peaks_px;
      if (options.store_images && f.image) {
        record.image = ToLogImage(*f.image);
        summary.images_stored = true;
      }
      GroundTruthRecord truth;
      truth.T_W_C = f.T_W_C;
      truth.points_W = f.truth_W;
      truth.object_ids = f.object_ids;
      writer.AppendFrame(record, &truth);
      summary.peaks += static_cast<std::int64_t>(f.peaks_px.size());
      ++summary.frames;
    }
    if (progress) progress(static_cast<double>(first + count) / total);
  }
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace uwscan::mapping
