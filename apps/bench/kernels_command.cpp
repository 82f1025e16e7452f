#include "apps/bench/kernels_command.hpp"

#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "apps/cli/number_validators.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"
#include "scanner/stripe/stripe_detector.hpp"
#include "scanner/stripe/stripe_render.hpp"
#include "scanner/triangulation/ray_ray_triangulator.hpp"
#include "scanner/triangulation/surface_triangulators.hpp"

namespace uwscan::app {
namespace {

struct KernelsArgs {
  int frames = 4;
  int points = 20000;
};

// Mirror steps the kernels use: a short sweep keeps the cone fits (not counted) quick under
// callgrind.
constexpr int kStepRange = 3;

void RunStripe(int frames) {
  scanner::StripeDetector detector;  // the default method
  scanner::StripeDetection detection;
  std::int64_t peaks = 0;
  for (int f = 0; f < frames; ++f) {
    scanner::StripeRenderOptions render;
    render.noise_sigma = 2.0;
    render.seed = 100 + f;
    scanner::StripeSpec stripe;
    stripe.centre.offset_px = 400.0 + 60.0 * f;
    stripe.centre.pivot_px = 1024.0;
    stripe.centre.slope = 0.03;
    stripe.centre.wave_px = 20.0;
    stripe.centre.period_px = 900.0;
    const scanner::StripeFrame frame = scanner::RenderStripes(render, {stripe});
    detector.Detect(frame.view(), &detection);
    peaks += std::ssize(detection.peaks);
  }
  std::printf("stripe_detector: %d frames of 2048x1088 Mono8, %lld peaks\n", frames,
              static_cast<long long>(peaks));
}

void RunTriangulators(int points) {
  scanner::GalvoScannerModel model = scanner::DefaultGalvoScannerModel();
  model.laser.step_min = -kStepRange;
  model.laser.step_max = kStepRange;
  auto rays = std::make_shared<const scanner::CameraRayTable>(model.camera);
  auto surfaces = std::make_shared<const scanner::LightSurfaceTable>(
      model.laser, scanner::LightSurfaceTableOptions{});
  const scanner::RayPlaneTriangulator ray_plane(rays, surfaces);
  const scanner::RayConeTriangulator ray_cone(rays, surfaces);
  const scanner::RayRayTriangulator ray_ray(model);
  // Frames of one peak per image row along a gentle curve, as a detector emits them.
  const int rows = model.camera.camera.height_px;
  std::vector<std::vector<Eigen::Vector2d>> frames;
  for (int done = 0; done < points; done += rows) {
    std::vector<Eigen::Vector2d>& peaks = frames.emplace_back();
    const int f = static_cast<int>(frames.size());
    for (int v = 0; v < rows && done + v < points; ++v) {
      peaks.emplace_back(1024.0 + 300.0 * std::sin(0.3 * f) + 80.0 * std::sin(0.004 * v + f),
                         v + 0.37);
    }
  }
  std::vector<scanner::TriangulatedPoint> out;
  for (const scanner::Triangulator* t : {static_cast<const scanner::Triangulator*>(&ray_plane),
                                         static_cast<const scanner::Triangulator*>(&ray_cone),
                                         static_cast<const scanner::Triangulator*>(&ray_ray)}) {
    std::int64_t hits = 0;
    for (size_t f = 0; f < frames.size(); ++f) {
      out.resize(frames[f].size());
      const int step = -kStepRange + static_cast<int>(f % (2 * kStepRange + 1));
      t->TriangulateFrame(step, frames[f], out);
      for (const scanner::TriangulatedPoint& p : out) hits += p.ok() ? 1 : 0;
    }
    std::printf("%s: %d points, %lld triangulated\n", scanner::ToString(t->method()), points,
                static_cast<long long>(hits));
  }
}

}  // namespace

void AddKernelsCommand(CLI::App& bench) {
  auto args = std::make_shared<KernelsArgs>();
  CLI::App* cmd = bench.add_subcommand(
      "kernels",
      "fixed work for each hot kernel, once (for bench/instructions.sh under callgrind)");
  cmd->add_option("--frames", args->frames, "stripe frames to detect")->check(kPositiveNumber);
  cmd->add_option("--points", args->points, "stripe pixels per triangulation method")
      ->check(kPositiveNumber);
  cmd->callback([args] {
    RunStripe(args->frames);
    RunTriangulators(args->points);
  });
}

}  // namespace uwscan::app
