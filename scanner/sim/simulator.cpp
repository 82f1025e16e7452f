#include "scanner/sim/simulator.hpp"

#include <cmath>
#include <limits>
#include <random>

#include "scanner/common/error.hpp"
#include "scanner/sim/effective_scanner.hpp"
#include "scanner/sim/frame_renderer.hpp"
#include "scanner/sim/light_source.hpp"
#include "scanner/sim/ray_caster.hpp"
#include "scanner/sim/stripe_tracer.hpp"

namespace uwscan::scanner::sim {
namespace {

// Laser rays whose backscatter is drawn per frame, and the spacing of glow samples along each.
constexpr int kGlowRaysPerFrame = 65;
constexpr double kGlowSpacingM = 0.02;
constexpr double kGlowStartM = 0.02;
constexpr double kGlowMaxRangeM = 3.0;
// A detected peak takes the truth of the exact crossing of its line within this distance.
constexpr double kTruthMatchPx = 3.0;
// Correlation time of the navigation's depth and roll/pitch errors, seconds.
constexpr double kAbsoluteErrorCorrelation_s = 5.0;
// Separates the random stream of the peak noise from the rendered frames' (same frame seeds).
constexpr std::uint64_t kPeakNoiseStream = 0x9e3779b97f4a7c15ULL;

std::uint64_t FrameSeed(std::uint64_t scene_seed, std::int64_t index) {
  std::seed_seq seq{static_cast<std::uint32_t>(scene_seed),
                    static_cast<std::uint32_t>(scene_seed >> 32), static_cast<std::uint32_t>(index),
                    static_cast<std::uint32_t>(index >> 32)};
  std::uint32_t words[2];
  seq.generate(words, words + 2);
  return (static_cast<std::uint64_t>(words[0]) << 32) | words[1];
}

std::unique_ptr<LightSource> MakeLightSource(const Scene& scene, const Scanner& scanner) {
  if (scanner.kind() == ScannerKind::kGalvo)
    return MakeGalvoLightSource(scanner.galvo(), scene.scanner.galvo);
  return MakeMemsLightSource(scanner.mems(), scene.scanner.mems, scene.effects.mirror_dynamics);
}

}  // namespace

struct Simulator::Impl {
  Scene scene;
  Scanner scanner;
  std::unique_ptr<LightSource> source;
  RayCaster caster;
  StripeTracer tracer;

  explicit Impl(const Scene& s)
      : scene(s),
        scanner(EffectiveScanner(s)),
        source(MakeLightSource(s, scanner)),
        caster(s.objects),
        tracer(source->camera(), caster,
               StripeTraceOptions{s.detector.axis, s.effects.occlusion, 25.0}) {}

  double FrameTime(std::int64_t index) const {
    return scene.trajectory.start_s() + static_cast<double>(index) * source->frame_period_s();
  }
  // The time whose pose a frame at `time_s` is simulated with: its own, or without the motion
  // stage the start of its sweep (the scanner holds still during a sweep).
  double PoseTime(double time_s) const {
    if (scene.effects.motion) return time_s;
    const double sweep_s = source->frames_per_sweep() * source->frame_period_s();
    const double start = scene.trajectory.start_s();
    const double sweep = std::floor((time_s - start) / sweep_s + 1e-9);
    return start + std::max(sweep, 0.0) * sweep_s;
  }

  std::vector<GlowSample> Glow(const LaserPath& path, const Eigen::Isometry3d& T_W_C) const;
  void DetectInImage(const std::vector<TracedPeak>& exact, SimulatedFrame* frame) const;
};

Simulator::Simulator(const Scene& scene) : impl_(std::make_unique<Impl>(scene)) {
  scene.effects.Check();
  scene.trajectory.Check();
  if (scene.scanner.sweeps < 1) throw Error(scene.source + ": scanner.sweeps must be >= 1");
}

Simulator::~Simulator() = default;

const Scene& Simulator::scene() const { return impl_->scene; }
const Scanner& Simulator::scanner() const { return impl_->scanner; }
double Simulator::frame_period_s() const { return impl_->source->frame_period_s(); }

ScanPattern Simulator::scan_pattern() const {
  ScanPattern pattern;
  pattern.kind = impl_->scanner.kind();
  pattern.galvo = impl_->scene.scanner.galvo;
  pattern.mems = impl_->scene.scanner.mems;
  return pattern;
}

std::int64_t Simulator::frame_count() const {
  return static_cast<std::int64_t>(impl_->scene.scanner.sweeps) * impl_->source->frames_per_sweep();
}

std::vector<GlowSample> Simulator::Impl::Glow(const LaserPath& path,
                                              const Eigen::Isometry3d& T_W_C) const {
  // Light scattered back by the water along each lit ray, as far as the ray goes, seen by the
  // camera with the inverse-square falloff of a small source.
  std::vector<GlowSample> glow;
  const RefractiveCamera& camera = source->camera();
  const double c = scene.effects.attenuation ? scene.water.attenuation_per_m : 0.0;
  const double per_sample = scene.effects.backscatter.level * kGlowSpacingM / kGlowRaysPerFrame;
  for (int k = 0; k < kGlowRaysPerFrame; ++k) {
    const double s = path.s_begin + (path.s_end - path.s_begin) * k / (kGlowRaysPerFrame - 1);
    const RayTrace laser = path.ray_in_water_C(s);
    if (!laser.ok()) continue;
    const Ray ray_W{T_W_C * laser.ray.origin, T_W_C.linear() * laser.ray.direction};
    const std::optional<SurfaceHit> hit = caster.Cast(ray_W);
    const double end = hit ? hit->distance_m : kGlowMaxRangeM;
    for (double t = kGlowStartM; t < end; t += kGlowSpacingM) {
      const Eigen::Vector3d p_C = laser.ray.At(t);
      const std::optional<Eigen::Vector2d> px = camera.ProjectPointInWater(p_C);
      if (!px || !camera.camera.InImage(*px)) continue;
      const double range = std::max(p_C.norm(), 0.05);
      glow.push_back({*px, per_sample * std::exp(-c * (t + range)) / (range * range)});
    }
  }
  return glow;
}

void Simulator::Impl::DetectInImage(const std::vector<TracedPeak>& exact,
                                    SimulatedFrame* frame) const {
  StripeDetector detector(scene.detector);
  const StripeDetection detection = detector.Detect(frame->image->view());
  const bool rows = scene.detector.axis == StripeAxis::kRows;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const StripePeak& peak : detection.peaks) {
    const Eigen::Vector2d px(peak.u_px, peak.v_px);
    const double line = rows ? px.y() : px.x();
    const double along = rows ? px.x() : px.y();
    // The exact crossing of the same line closest to the detected one is its truth.
    const TracedPeak* best = nullptr;
    double best_distance = kTruthMatchPx;
    for (const TracedPeak& t : exact) {
      if ((rows ? t.px.y() : t.px.x()) != line) continue;
      const double distance = std::abs((rows ? t.px.x() : t.px.y()) - along);
      if (distance <= best_distance) {
        best_distance = distance;
        best = &t;
      }
    }
    frame->peaks_px.push_back(px);
    frame->truth_W.push_back(best ? best->p_W : Eigen::Vector3d::Constant(nan));
    frame->object_ids.push_back(best ? best->object_index : -1);
    frame->crossing_px.push_back(best ? best->px : Eigen::Vector2d::Constant(nan));
  }
}

SimulatedFrame Simulator::Frame(std::int64_t index) const {
  const Impl& m = *impl_;
  if (index < 0 || index >= frame_count()) {
    throw Error("simulator: frame " + std::to_string(index) + " out of range [0, " +
                std::to_string(frame_count()) + ")");
  }
  const int per_sweep = m.source->frames_per_sweep();
  SimulatedFrame frame;
  frame.index = index;
  frame.sweep = static_cast<int>(index / per_sweep);
  const int in_sweep = static_cast<int>(index % per_sweep);
  frame.command = m.source->CommandOfFrame(in_sweep);
  frame.time_s = m.FrameTime(index);
  // Without the motion stage the scanner holds the pose it had when the sweep began.
  frame.T_W_C = m.scene.trajectory.T_W_C(
      m.scene.effects.motion ? frame.time_s
                             : m.FrameTime(static_cast<std::int64_t>(frame.sweep) * per_sweep));

  const LaserPath path = m.source->PathOfFrame(in_sweep);
  const std::vector<TracedPeak> exact = m.tracer.Trace(path, frame.T_W_C);
  if (!m.scene.effects.AnyImageStage()) {
    const SimulationEffects::PeakNoise& noise = m.scene.effects.peak_noise;
    std::mt19937_64 rng(FrameSeed(m.scene.seed ^ kPeakNoiseStream, index));
    std::normal_distribution<double> along(0.0, noise.sigma_px);
    const int along_axis = m.scene.detector.axis == StripeAxis::kRows ? 0 : 1;
    const PinholeCamera& camera = m.source->camera().camera;
    const double along_size_px = along_axis == 0 ? camera.width_px : camera.height_px;
    for (const TracedPeak& peak : exact) {
      Eigen::Vector2d px = peak.px;
      if (noise.on) px[along_axis] += along(rng);
      // A crossing at the sensor's edge that the noise moved off it: no detector reports it.
      if (px[along_axis] < -0.5 || px[along_axis] > along_size_px - 0.5) continue;
      frame.peaks_px.push_back(px);
      frame.truth_W.push_back(peak.p_W);
      frame.object_ids.push_back(peak.object_index);
      frame.crossing_px.push_back(peak.px);
    }
    return frame;
  }

  FrameRenderInput input;
  const PinholeCamera& camera = m.source->camera().camera;
  input.width_px = camera.width_px;
  input.height_px = camera.height_px;
  input.focal_px = 0.5 * (camera.fx_px + camera.fy_px);
  input.axis = m.scene.detector.axis;
  input.peaks = exact;
  input.attenuation_per_m = m.scene.water.attenuation_per_m;
  if (m.scene.effects.backscatter.on) input.glow = m.Glow(path, frame.T_W_C);
  frame.image = RenderFrame(input, m.scene.effects, FrameSeed(m.scene.seed, index));
  m.DetectInImage(exact, &frame);
  return frame;
}

std::vector<NavigationSample> Simulator::Navigation(double rate_hz) const {
  if (!(rate_hz > 0.0)) throw Error("simulator: navigation rate must be > 0 Hz");
  const Impl& m = *impl_;
  const double start = m.FrameTime(0);
  const double end = m.FrameTime(std::max<std::int64_t>(frame_count() - 1, 0));
  const double dt = 1.0 / rate_hz;
  const SimulationEffects::NavigationDrift& drift = m.scene.effects.navigation_drift;
  std::mt19937_64 rng(FrameSeed(m.scene.seed, -1));
  std::normal_distribution<double> normal(0.0, 1.0);
  // Drawn once per dive: the DVL's speed scale error and the compass's heading bias.
  const double speed_scale = 1.0 + (drift.on ? drift.speed_scale_sigma * normal(rng) : 0.0);
  const double heading_bias = drift.on ? drift.heading_bias_sigma_rad * normal(rng) : 0.0;
  double heading_walk = 0.0;
  double depth_error = 0.0;
  Eigen::Vector2d tilt_error = Eigen::Vector2d::Zero();
  Eigen::Vector2d believed_xy = Eigen::Vector2d::Zero();
  Eigen::Vector3d previous_true = Eigen::Vector3d::Zero();
  std::vector<NavigationSample> samples;
  // One sample at or past the last frame, so that every frame time is bracketed.
  for (int k = 0;; ++k) {
    const double t = start + k * dt;
    if (k > 0 && t - dt >= end) break;
    NavigationSample sample;
    sample.time_s = t;
    // The navigation reports the pose the frames were simulated with (held during a sweep
    // without the motion stage), so that reconstruction places them where they were taken.
    const Eigen::Isometry3d truth = m.scene.trajectory.T_W_V(m.PoseTime(t));
    sample.T_W_V = truth;
    if (drift.on) {
      const double sq = std::sqrt(dt);
      if (k == 0) {
        believed_xy = truth.translation().head<2>();  // dead reckoning starts from a known fix
      } else {
        heading_walk += drift.yaw_walk_rad_per_sqrt_s * sq * normal(rng);
      }
      // Dead reckoning: the true horizontal displacement as the DVL measures it (scaled),
      // turned by the heading error, plus the random walk of the position.
      const double heading_error = heading_bias + heading_walk;
      const Eigen::Rotation2Dd turn(heading_error);
      if (k > 0) {
        const Eigen::Vector2d moved = (truth.translation() - previous_true).head<2>();
        // y is drawn before x: the order g++ gave the former Vector2d(normal(rng), normal(rng)),
        // kept so that dives simulated before stay the same.
        const double walk_y = normal(rng);
        const double walk_x = normal(rng);
        believed_xy += speed_scale * (turn * moved) +
                       drift.position_walk_m_per_sqrt_s * sq * Eigen::Vector2d(walk_x, walk_y);
      }
      previous_true = truth.translation();
      // Absolute sensors: depth from pressure, roll and pitch from gravity (errors about the
      // vehicle's own x and y axes), heading with its drift about the world's down axis (the
      // bias is the DVL's misalignment: it turns the measured velocity, not the heading). The
      // navigation filter smooths its sensors: their errors wander (first-order Gauss-Markov,
      // std as given, correlation time kAbsoluteErrorCorrelation_s) rather than jump per sample.
      const double keep = k == 0 ? 0.0 : std::exp(-dt / kAbsoluteErrorCorrelation_s);
      const double fresh = std::sqrt(1.0 - keep * keep);
      depth_error = keep * depth_error + fresh * drift.depth_sigma_m * normal(rng);
      for (int axis = 0; axis < 2; ++axis) {
        tilt_error[axis] =
            keep * tilt_error[axis] + fresh * drift.roll_pitch_sigma_rad * normal(rng);
      }
      const double depth_noise = depth_error;
      const Eigen::Vector3d tilt_noise(tilt_error[0], tilt_error[1], 0.0);
      const double tilt_angle = tilt_noise.norm();
      const Eigen::Matrix3d tilt =
          tilt_angle > 0.0
              ? Eigen::AngleAxisd(tilt_angle, tilt_noise / tilt_angle).toRotationMatrix()
              : Eigen::Matrix3d::Identity();
      sample.T_W_V.linear() =
          Eigen::AngleAxisd(heading_walk, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
          truth.linear() * tilt;
      sample.T_W_V.translation() << believed_xy, truth.translation().z() + depth_noise;
    }
    samples.push_back(sample);
  }
  return samples;
}

std::vector<double> PeakErrorsPx(const SimulatedFrame& frame, StripeAxis axis) {
  if (frame.crossing_px.size() != frame.peaks_px.size()) {
    throw Error("PeakErrorsPx: frame " + std::to_string(frame.index) + " has " +
                std::to_string(frame.peaks_px.size()) + " peaks but " +
                std::to_string(frame.crossing_px.size()) + " crossings");
  }
  const int along = axis == StripeAxis::kRows ? 0 : 1;
  std::vector<double> errors;
  for (std::size_t k = 0; k < frame.peaks_px.size(); ++k) {
    if (std::isfinite(frame.crossing_px[k][along]))
      errors.push_back(frame.peaks_px[k][along] - frame.crossing_px[k][along]);
  }
  return errors;
}

}  // namespace uwscan::scanner::sim
