#include "bench/scanner/triangulation_benchmark.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "scanner/common/option_checks.hpp"
#include "scanner/triangulation/ray_ray_triangulator.hpp"
#include "scanner/triangulation/surface_triangulators.hpp"

namespace uwscan::bench {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct Frame {
  int step = 0;
  std::vector<Eigen::Vector2d> peaks_px;
  std::vector<Eigen::Vector3d> truth_C;
};

// A stripe detector scans the image row by row and emits its peaks in that order.
void SortLikeADetector(Frame* frame) {
  std::vector<size_t> order(frame->peaks_px.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const Eigen::Vector2d& pa = frame->peaks_px[a];
    const Eigen::Vector2d& pb = frame->peaks_px[b];
    return pa.y() != pb.y() ? pa.y() < pb.y() : pa.x() < pb.x();
  });
  Frame sorted;
  sorted.step = frame->step;
  for (size_t i : order) {
    sorted.peaks_px.push_back(frame->peaks_px[i]);
    sorted.truth_C.push_back(frame->truth_C[i]);
  }
  *frame = std::move(sorted);
}

// Draws frames as a scanner sees them: at each mirror step the fan lights a smooth surface
// (depth a random sinusoid of the fan angle, its mean anywhere in the depth range), so the
// stripe crosses the image with one peak per fan sample. Points the camera cannot see are
// dropped; the frame's peaks are then sorted like a detector's output.
std::vector<Frame> MakeFrames(const scanner::GalvoScannerModel& model,
                              const TriangulationBenchOptions& o, const Progress& progress) {
  std::mt19937_64 rng(o.seed);
  const scanner::GalvoLaser& laser = model.laser;
  std::uniform_int_distribution<int> step_dist(laser.step_min, laser.step_max);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double half_aperture = 0.5 * laser.aperture_rad;
  const double span = o.depth_max_m - o.depth_min_m;

  std::vector<Frame> frames;
  std::int64_t total = 0;
  while (total < o.points) {
    Frame frame;
    frame.step = step_dist(rng);
    const scanner::LaserFan fan = laser.FanAtStep(frame.step);
    const double amplitude = 0.1 * span * unit(rng);
    const double mean = o.depth_min_m + amplitude + (span - 2.0 * amplitude) * unit(rng);
    const double frequency = 2.0 + 10.0 * unit(rng), phase = 6.283 * unit(rng);
    const std::int64_t want = std::min<std::int64_t>(o.points_per_frame, o.points - total);
    // Twice as many fan samples as wanted peaks: the camera sees only part of the fan.
    const std::int64_t samples = 2 * want;
    for (std::int64_t k = 0; k < samples && std::ssize(frame.peaks_px) < want; ++k) {
      const double angle = -half_aperture + (k + unit(rng)) * (2.0 * half_aperture / samples);
      const double depth = mean + amplitude * std::sin(frequency * angle + phase);
      const scanner::RayTrace ray = fan.RayInWater(std::tan(angle));
      if (!ray.ok() || ray.ray.direction.z() <= 1e-6) continue;
      const Eigen::Vector3d p = ray.ray.At((depth - ray.ray.origin.z()) / ray.ray.direction.z());
      const std::optional<Eigen::Vector2d> uv = model.camera.ProjectPointInWater(p);
      if (!uv || !model.camera.camera.InImage(*uv)) continue;
      frame.peaks_px.push_back(*uv);
      frame.truth_C.push_back(p);
    }
    SortLikeADetector(&frame);
    total += std::ssize(frame.peaks_px);
    if (!frame.peaks_px.empty()) frames.push_back(std::move(frame));
    if (progress) progress("generating stripe pixels", static_cast<double>(total) / o.points);
  }
  return frames;
}

using Points = std::vector<std::vector<scanner::TriangulatedPoint>>;
using FrameKernel = std::function<void(const Frame&, std::vector<scanner::TriangulatedPoint>&)>;

// A kernel to time: its name, what it does to one frame, and where its points go.
struct TimedKernel {
  std::string name;
  FrameKernel triangulate_frame;
  Points* results = nullptr;
};

// Runs every kernel over every frame, `repeats` passes, the kernels in turn within each pass so
// that they meet the same load from the rest of the machine; returns each kernel's fastest pass
// (the least disturbed by that load: the machines here are shared). With several kernels, a whole
// pass of the others between two runs of one leaves the caches as cold for each.
std::vector<double> TimeInterleaved(const std::vector<Frame>& frames, int repeats,
                                    const std::vector<TimedKernel>& kernels,
                                    const Progress& progress) {
  for (const TimedKernel& kernel : kernels) {
    kernel.results->resize(frames.size());
    for (size_t f = 0; f < frames.size(); ++f) {
      (*kernel.results)[f].resize(frames[f].peaks_px.size());
    }
  }
  std::vector<double> best(kernels.size(), std::numeric_limits<double>::infinity());
  for (int pass = 0; pass < repeats; ++pass) {
    for (size_t k = 0; k < kernels.size(); ++k) {
      const Clock::time_point start = Clock::now();
      for (size_t f = 0; f < frames.size(); ++f) {
        kernels[k].triangulate_frame(frames[f], (*kernels[k].results)[f]);
      }
      best[k] = std::min(best[k], SecondsSince(start));
    }
    if (progress)
      progress(kernels.size() == 1 ? kernels.front().name : "table methods and limit",
               (pass + 1.0) / repeats);
  }
  return best;
}

TimedKernel MethodKernel(const scanner::Triangulator& method, Points* results) {
  return {ToString(method.method()),
          [&method](const Frame& frame, std::vector<scanner::TriangulatedPoint>& out) {
            method.TriangulateFrame(frame.step, frame.peaks_px, out);
          },
          results};
}

double RunMethod(const scanner::Triangulator& method, const std::vector<Frame>& frames, int repeats,
                 Points* results, const Progress& progress) {
  return TimeInterleaved(frames, repeats, {MethodKernel(method, results)}, progress)[0];
}

// The floor of any table method over the same pixels: each peak's camera ray looked up in the
// table (prefetched ahead, as the methods do) and one multiply-add per coordinate, o + s d,
// with a per-frame s standing for the surface. No intersection, no tests.
TimedKernel LimitKernel(const scanner::CameraRayTable& rays, Points* results) {
  return {"limit",
          [&rays](const Frame& frame, std::vector<scanner::TriangulatedPoint>& out) {
            const std::vector<Eigen::Vector2d>& px = frame.peaks_px;
            const double s = 1.0 + 1e-3 * frame.step;
            constexpr size_t kAhead = scanner::CameraRayTable::kPrefetchAhead;
            const scanner::CameraRayTable::Grid table = rays.grid();
            scanner::Ray ray;
            for (size_t i = 0; i < px.size(); ++i) {
              if (i + kAhead < px.size()) table.Prefetch(px[i + kAhead].x(), px[i + kAhead].y());
              const bool in = table.Lookup(px[i].x(), px[i].y(), &ray);
              out[i].p_C = ray.origin + s * ray.direction;
              out[i].status = in ? scanner::HitStatus::kHit : scanner::HitStatus::kNoIntersection;
            }
          },
          results};
}

// Mean, standard deviation and maximum of |method - reference| over points both produced.
void CompareTo(const Points& result, const Points& reference, MethodFigures* figures) {
  double sum = 0.0, sum2 = 0.0, max = 0.0;
  std::int64_t n = 0, triangulated = 0;
  for (size_t f = 0; f < result.size(); ++f) {
    for (size_t i = 0; i < result[f].size(); ++i) {
      if (!result[f][i].ok()) continue;
      ++triangulated;
      if (!reference[f][i].ok()) continue;
      const double e = (result[f][i].p_C - reference[f][i].p_C).norm();
      sum += e, sum2 += e * e, max = std::max(max, e), ++n;
    }
  }
  figures->triangulated = triangulated;
  if (n == 0) return;
  figures->mean_err_m = sum / n;
  figures->std_err_m =
      std::sqrt(std::max(0.0, sum2 / n - figures->mean_err_m * figures->mean_err_m));
  figures->max_err_m = max;
}

void SetRate(std::int64_t points, MethodFigures* figures) {
  figures->points_per_s = figures->seconds > 0.0 ? points / figures->seconds : 0.0;
}

// The table methods with these tables on the frames, against the exact points.
TableResolutionRow MeasureTables(std::shared_ptr<const scanner::CameraRayTable> rays,
                                 std::shared_ptr<const scanner::LightSurfaceTable> surfaces,
                                 const std::vector<Frame>& frames, std::int64_t points,
                                 const Points& exact, int repeats) {
  TableResolutionRow row;
  Points approximate;
  const scanner::RayPlaneTriangulator ray_plane(rays, surfaces);
  const scanner::RayConeTriangulator ray_cone(rays, surfaces);
  row.ray_plane.seconds = RunMethod(ray_plane, frames, repeats, &approximate, {});
  CompareTo(approximate, exact, &row.ray_plane);
  SetRate(points, &row.ray_plane);
  row.ray_cone.seconds = RunMethod(ray_cone, frames, repeats, &approximate, {});
  CompareTo(approximate, exact, &row.ray_cone);
  SetRate(points, &row.ray_cone);
  return row;
}

// Each table resolution of the options in turn, the other table at its default.
std::vector<TableResolutionRow> SweepResolutions(
    const scanner::GalvoScannerModel& model, const TriangulationBenchOptions& o,
    std::shared_ptr<const scanner::CameraRayTable> default_rays,
    std::shared_ptr<const scanner::LightSurfaceTable> default_surfaces,
    const std::vector<Frame>& frames, std::int64_t points, const Points& exact,
    const Progress& progress) {
  std::vector<TableResolutionRow> rows;
  const double total =
      static_cast<double>(o.sweep_camera_grid_px.size() + o.sweep_rays_per_fan.size());
  const auto add = [&](const char* table, int value, double setup_s, TableResolutionRow row) {
    row.table = table;
    row.value = value;
    row.setup_s = setup_s;
    rows.push_back(std::move(row));
    if (progress) progress("table resolutions", rows.size() / total);
  };
  for (const int grid_px : o.sweep_camera_grid_px) {
    const Clock::time_point start = Clock::now();
    auto rays = std::make_shared<const scanner::CameraRayTable>(model.camera, grid_px);
    const double setup_s = SecondsSince(start);
    add("camera_rays", grid_px, setup_s,
        MeasureTables(rays, default_surfaces, frames, points, exact, o.sweep_repeats));
  }
  for (const int rays_per_fan : o.sweep_rays_per_fan) {
    scanner::LightSurfaceTableOptions surface_options = o.surfaces;
    surface_options.rays_per_fan = rays_per_fan;
    const Clock::time_point start = Clock::now();
    auto surfaces =
        std::make_shared<const scanner::LightSurfaceTable>(model.laser, surface_options);
    const double setup_s = SecondsSince(start);
    add("light_surfaces", rays_per_fan, setup_s,
        MeasureTables(default_rays, surfaces, frames, points, exact, o.sweep_repeats));
  }
  return rows;
}

}  // namespace

void TriangulationBenchOptions::Check() const {
  const OptionChecks check("TriangulationBenchOptions");
  check.AtLeast("points", points, 1);
  check.AtLeast("points_per_frame", points_per_frame, 1);
  check.GreaterThan("depth_min_m", depth_min_m, 0.0, "m");
  check.Require(depth_max_m > depth_min_m, "depth_max_m",
                "> depth_min_m (" + OptionValueText(depth_min_m) + " m)", depth_max_m);
  check.AtLeast("repeats", repeats, 1);
  check.AtLeast("exact_repeats", exact_repeats, 1);
  check.AtLeast("sweep_repeats", sweep_repeats, 1);
  check.AtLeast("camera_grid_px", camera_grid_px, 1, "px");
  surfaces.Check();
  for (std::size_t i = 0; i < sweep_camera_grid_px.size(); ++i) {
    if (sweep_camera_grid_px[i] < 1) {
      check.Fail("sweep_camera_grid_px[" + std::to_string(i) + "]", ">= 1 px",
                 std::to_string(sweep_camera_grid_px[i]));
    }
  }
  for (const int r : sweep_rays_per_fan) {
    scanner::LightSurfaceTableOptions swept = surfaces;
    swept.rays_per_fan = r;
    swept.Check();
  }
}

TriangulationBenchResult RunTriangulationBenchmark(const scanner::GalvoScannerModel& model,
                                                   const TriangulationBenchOptions& o,
                                                   const Progress& progress) {
  o.Check();
  model.Check();
  TriangulationBenchResult result;

  Clock::time_point start = Clock::now();
  if (progress) progress("fitting planes and cones per mirror step", 0.0);
  auto rays = std::make_shared<const scanner::CameraRayTable>(model.camera, o.camera_grid_px);
  auto surfaces = std::make_shared<const scanner::LightSurfaceTable>(model.laser, o.surfaces);
  const scanner::RayPlaneTriangulator ray_plane(rays, surfaces);
  const scanner::RayConeTriangulator ray_cone(rays, surfaces);
  const scanner::RayRayTriangulator ray_ray(model);
  result.setup_s = SecondsSince(start);
  if (progress) progress("fitting planes and cones per mirror step", 1.0);

  const std::vector<Frame> frames = MakeFrames(model, o, progress);
  for (const Frame& f : frames) result.points += std::ssize(f.peaks_px);

  Points exact;
  MethodFigures& exact_figures = result.methods[ToString(scanner::TriangulationMethod::kRayRay)];
  exact_figures.seconds = RunMethod(ray_ray, frames, o.exact_repeats, &exact, progress);
  CompareTo(exact, exact, &exact_figures);
  for (size_t f = 0; f < frames.size(); ++f) {
    for (size_t i = 0; i < frames[f].truth_C.size(); ++i) {
      if (!exact[f][i].ok()) continue;
      result.exact_vs_truth_max_m =
          std::max(result.exact_vs_truth_max_m, (exact[f][i].p_C - frames[f].truth_C[i]).norm());
    }
  }
  // The table methods and their limit timed side by side, so that their ratio holds in one load.
  Points plane_points, cone_points, limit_points;
  const std::vector<double> seconds =
      TimeInterleaved(frames, o.repeats,
                      {LimitKernel(*rays, &limit_points), MethodKernel(ray_plane, &plane_points),
                       MethodKernel(ray_cone, &cone_points)},
                      progress);
  result.limit_seconds = seconds[0];
  result.limit_points_per_s = result.points / result.limit_seconds;
  const auto record = [&](const scanner::Triangulator& method, const Points& points, double s) {
    MethodFigures& figures = result.methods[ToString(method.method())];
    figures.seconds = s;
    CompareTo(points, exact, &figures);
  };
  record(ray_plane, plane_points, seconds[1]);
  record(ray_cone, cone_points, seconds[2]);
  for (auto& [name, figures] : result.methods) {
    SetRate(result.points, &figures);
    figures.fraction_of_limit = figures.points_per_s / result.limit_points_per_s;
  }
  result.resolution =
      SweepResolutions(model, o, rays, surfaces, frames, result.points, exact, progress);
  return result;
}

}  // namespace uwscan::bench
