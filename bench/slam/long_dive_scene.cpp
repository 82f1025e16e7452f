#include "bench/slam/long_dive_scene.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::bench {
namespace {

constexpr double kRowLength_m = 8.0;   // each pipeline runs from x = 0 to here
constexpr double kRowSpacing_m = 1.5;  // between pipelines, along y
constexpr int kRows = 3;
constexpr double kAltitudeDepth_m = 9;  // the vehicle's depth, 1 m above the seabed
constexpr double kSpeed_mps = 0.25;
constexpr double kTurn_s = 3.0;       // a quarter turn in place
constexpr double kLegStart_m = -0.3;  // where a leg along a pipeline starts and ends
constexpr double kLegEnd_m = 8.0;
constexpr double kFrameRate_hz = 100.0;
constexpr int kFramesPerSweep = 51;    // steps -100..100 by 4
constexpr double kPipeDepth_m = 9.92;  // axis of a pipe of radius 0.08 lying on the seabed

const char* const kAlongX = "[0, 0.7071067812, 0, 0.7071067812]";

std::string Number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", value);
  return text;
}

std::string Pose(double x, double y, double z, const std::string& rotation_xyzw) {
  return "pose: {translation_m: [" + Number(x) + ", " + Number(y) + ", " + Number(z) +
         "], rotation_xyzw: " + rotation_xyzw + "}";
}

// A pipeline component centred at x along the pipe: its kind, and how far it reaches each way.
struct Component {
  double x;
  char kind;  // 'f' flange, 'v' valve, 't' tee with a branch towards +y
  double half_length() const { return kind == 'f' ? 0.15 : kind == 'v' ? 0.13 : 0.3; }
};

void AddComponent(const Component& c, double y, const std::string& name, std::ostringstream& out) {
  if (c.kind == 'f') {
    out << "  - {name: " << name << ", shape: flange, outer_radius_m: 0.08, wall_m: 0.008, "
        << "length_m: 0.3, flange_radius_m: 0.14, flange_thickness_m: 0.025, bolts: 8, "
        << "reflectance: 0.5,\n     " << Pose(c.x, y, kPipeDepth_m, kAlongX) << "}\n";
  } else if (c.kind == 'v') {
    out << "  - {name: " << name << ", shape: valve, outer_radius_m: 0.08, wall_m: 0.008, "
        << "body_radius_m: 0.11, body_length_m: 0.16, stub_length_m: 0.05, stem_length_m: 0.18, "
        << "handle: wheel, handle_radius_m: 0.09, reflectance: 0.6,\n     "
        << Pose(c.x, y, kPipeDepth_m, "[-0.5, 0.5, -0.5, 0.5]") << "}\n";
  } else {
    out << "  - {name: " << name << ", shape: tee, outer_radius_m: 0.08, wall_m: 0.008, "
        << "run_length_m: 0.6, branch_length_m: 0.25, reflectance: 0.5,\n     "
        << Pose(c.x, y, kPipeDepth_m, "[0.5, 0.5, 0.5, 0.5]") << "}\n";
    out << "  - {name: " << name << "_branch, shape: pipe, outer_radius_m: 0.08, wall_m: 0.008, "
        << "length_m: 0.5, reflectance: 0.5,\n     "
        << Pose(c.x, y + 0.5, kPipeDepth_m, "[-0.7071067812, 0, 0, 0.7071067812]") << "}\n";
  }
}

void AddPipe(double from_x, double to_x, double y, const std::string& name,
             std::ostringstream& out) {
  if (to_x - from_x < 0.05) return;
  out << "  - {name: " << name
      << ", shape: pipe, outer_radius_m: 0.08, wall_m: 0.008, length_m: " << Number(to_x - from_x)
      << ", reflectance: 0.5,\n     " << Pose(0.5 * (from_x + to_x), y, kPipeDepth_m, kAlongX)
      << "}\n";
}

// Pipeline r: its components in order along x, pipe between them.
void AddPipeline(int r, std::ostringstream& out) {
  static const std::vector<std::vector<Component>> kLayouts = {
      {{1.5, 'f'}, {3.4, 'v'}, {5.6, 't'}},
      {{1.9, 'v'}, {4.0, 't'}, {6.3, 'f'}},
      {{1.2, 't'}, {3.9, 'f'}, {5.2, 'v'}}};
  const double y = kRowSpacing_m * r;
  const std::string row = "line" + std::to_string(r);
  double x = 0.0;
  int piece = 0;
  for (const Component& c : kLayouts[static_cast<size_t>(r)]) {
    AddPipe(x, c.x - c.half_length(), y, row + "_pipe" + std::to_string(piece++), out);
    AddComponent(c, y, row + (c.kind == 'f' ? "_flange" : c.kind == 'v' ? "_valve" : "_tee"), out);
    x = c.x + c.half_length();
  }
  AddPipe(x, kRowLength_m, y, row + "_pipe" + std::to_string(piece), out);
}

// Debris beside the pipelines at fixed, irregular places (a low-discrepancy sequence), so
// that the seabed between them is not bare.
void AddDebris(std::ostringstream& out) {
  for (int i = 0; i < 24; ++i) {
    const double u = std::fmod(0.6180339887 * (i + 1), 1.0);
    const double v = std::fmod(0.7548776662 * (i + 1), 1.0);
    const double x = 0.3 + u * (kRowLength_m - 0.6);
    // Between 0.35 and 0.75 m to either side of the nearest pipeline.
    const int row = i % kRows;
    const double side = (i / kRows) % 2 == 0 ? 1.0 : -1.0;
    const double y = kRowSpacing_m * row + side * (0.35 + 0.4 * v);
    const double yaw = 3.0 * u;
    const std::string rotation =
        "[0, 0, " + Number(std::sin(0.5 * yaw)) + ", " + Number(std::cos(0.5 * yaw)) + "]";
    const std::string name = "debris_" + std::to_string(i);
    switch (i % 3) {
      case 0:
        out << "  - {name: " << name << ", shape: box, size_m: [" << Number(0.12 + 0.2 * v) << ", "
            << Number(0.08 + 0.1 * u) << ", " << Number(0.06 + 0.1 * v)
            << "], reflectance: 0.5,\n     " << Pose(x, y, 10.0 - 0.5 * (0.06 + 0.1 * v), rotation)
            << "}\n";
        break;
      case 1:
        out << "  - {name: " << name << ", shape: cylinder, radius_m: " << Number(0.06 + 0.05 * v)
            << ", length_m: " << Number(0.25 + 0.3 * u) << ", reflectance: 0.5,\n     "
            << Pose(x, y, 10.0 - (0.06 + 0.05 * v), kAlongX) << "}\n";
        break;
      default:
        out << "  - {name: " << name << ", shape: sphere, radius_m: " << Number(0.06 + 0.06 * u)
            << ", reflectance: 0.5,\n     " << Pose(x, y, 10.0 - (0.06 + 0.06 * u), "[0, 0, 0, 1]")
            << "}\n";
    }
  }
}

struct Waypoint {
  double time_s, x, y, yaw_rad;
};

// The laps: up line 0, down line 1, up line 2, back across the far ends to line 0; then the same
// the other way round; until duration_s. Headings: 0 up (+x, north), pi/2 east, pi down.
std::vector<Waypoint> Laps(double duration_s) {
  std::vector<Waypoint> path = {{0.0, kLegStart_m, 0.0, 0.0}};
  // Turns in place the shorter way to `heading`, then moves straight to (x, y).
  const auto go = [&path](double x, double y, double heading) {
    Waypoint w = path.back();
    const double turn = std::remainder(heading - w.yaw_rad, 2.0 * M_PI);
    if (std::abs(turn) > 1e-9) {
      w.time_s += kTurn_s;
      w.yaw_rad += turn;
      path.push_back(w);
    }
    w.time_s += std::hypot(x - w.x, y - w.y) / kSpeed_mps;
    w.x = x;
    w.y = y;
    path.push_back(w);
  };
  const double east = 0.5 * M_PI;
  for (int lap = 0; path.back().time_s < duration_s; ++lap) {
    for (int r = 0; r < kRows; ++r) {
      const bool up = (r + lap) % 2 == 0;
      if (r > 0) go(path.back().x, kRowSpacing_m * r, east);
      go(up ? kLegEnd_m : kLegStart_m, kRowSpacing_m * r, up ? 0.0 : M_PI);
    }
    go(path.back().x, 0.0, -east);
  }
  return path;
}

// A YAML single-quoted scalar: any path, whatever characters it holds.
std::string SingleQuoted(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("''") : std::string(1, c);
  return quoted + "'";
}

}  // namespace

std::string LongDiveSceneYaml(double duration_s, std::uint64_t seed,
                              const std::string& scanner_file) {
  if (!(duration_s > 0.0) || !std::isfinite(duration_s))
    throw Error("long dive scene: duration_s must be finite and > 0, got " + Number(duration_s));
  std::ostringstream out;
  out << "# The long-dive bench's manifold field, " << Number(duration_s)
      << " s (bench/slam/long_dive_scene.hpp).\n"
      << "uwscan_format: 1\nseed: " << seed << "\n"
      << "water: {refractive_index: 1.33, attenuation_per_m: 0.2}\n"
      << "scanner:\n  file: " << SingleQuoted(scanner_file) << "\n  sweeps: "
      << static_cast<int>(std::floor(duration_s * kFrameRate_hz / kFramesPerSweep)) << "\n"
      << "  galvo: {step_min: -100, step_max: 100, step_stride: 4, frame_rate_hz: 100}\n"
      << "trajectory:\n"
      << "  T_V_C: {translation_m: [0.3, 0, 0.2], rotation_xyzw: [0, 0.1736481777, 0, "
         "0.984807753]}\n"
      << "  poses:\n";
  for (const Waypoint& w : Laps(duration_s)) {
    out << "    - {time_s: " << Number(w.time_s) << ", T_W_V: {translation_m: [" << Number(w.x)
        << ", " << Number(w.y) << ", " << Number(kAltitudeDepth_m) << "], rotation_xyzw: [0, 0, "
        << Number(std::sin(0.5 * w.yaw_rad)) << ", " << Number(std::cos(0.5 * w.yaw_rad))
        << "]}}\n";
  }
  out << "effects:\n  refraction: true\n  lens_distortion: true\n  occlusion: true\n"
      << "  motion: true\n"
      << "  navigation_drift: {position_walk_m_per_sqrt_s: 0.003, yaw_walk_rad_per_sqrt_s: 0.0005, "
         "speed_scale_sigma: 0.01, heading_bias_sigma_rad: 0.01, depth_sigma_m: 0.001, "
         "roll_pitch_sigma_rad: 0.0005}\n"
      << "  peak_noise: {sigma_px: 0.15}\n"
      << "objects:\n"
      << "  - {name: seabed, shape: plane, size_m: [14, 8], reflectance: 0.3,\n     "
      << Pose(4.0, 1.5, 10.0, "[1, 0, 0, 0]") << "}\n";
  for (int r = 0; r < kRows; ++r) AddPipeline(r, out);
  // The protection frame across the far ends (its face 0.8 m beyond them) and mudmats across
  // the near ones: what pins the along-track position at each end of a leg.
  out << "  - {name: frame, shape: box, size_m: [0.3, 4.5, 1.2], reflectance: 0.4,\n     "
      << Pose(kRowLength_m + 0.95, 1.5, 9.4, "[0, 0, 0, 1]") << "}\n"
      << "  - {name: mudmat, shape: box, size_m: [0.5, 4.0, 0.2], reflectance: 0.4,\n     "
      << Pose(-0.7, 1.5, 9.9, "[0, 0, 0.0871557427, 0.9961946981]") << "}\n";
  AddDebris(out);
  return out.str();
}

}  // namespace uwscan::bench
