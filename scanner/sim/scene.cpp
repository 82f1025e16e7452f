#include "scanner/sim/scene.hpp"

#include <fstream>
#include <functional>
#include <optional>
#include <sstream>

#include "scanner/common/error.hpp"
#include "scanner/common/yaml_fields.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/scene_fields.hpp"
#include "scanner/sim/scene_objects.hpp"

namespace uwscan::scanner::sim {
namespace {

using namespace scene_yaml;

std::optional<std::string> ReadText(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// --- water, scanner, trajectory -------------------------------------------------------------

Water ReadWater(const Context& where, const YAML::Node& node) {
  yaml::RequireKnownKeys(where, node, {"refractive_index", "attenuation_per_m"});
  Water w;
  w.refractive_index =
      Number(where, node, "refractive_index", Range::kAtLeastOne, w.refractive_index);
  w.attenuation_per_m =
      Number(where, node, "attenuation_per_m", Range::kNonNegative, w.attenuation_per_m);
  return w;
}

GalvoScan ReadGalvo(const Context& where, const YAML::Node& node, const GalvoLaser& laser) {
  yaml::RequireKnownKeys(where, node, {"step_min", "step_max", "step_stride", "frame_rate_hz"});
  GalvoScan g;
  // The sweep defaults to the laser's whole step range.
  g.step_min = Has(node, "step_min") ? yaml::Integer(where, node, "step_min") : laser.step_min;
  g.step_max = Has(node, "step_max") ? yaml::Integer(where, node, "step_max") : laser.step_max;
  g.step_stride = Integer(where, node, "step_stride", 1, g.step_stride);
  g.frame_rate_hz = Number(where, node, "frame_rate_hz", Range::kPositive, g.frame_rate_hz);
  // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "[" + std::to_string(..).
  std::string range = "[";
  range += std::to_string(laser.step_min);
  range += ", ";
  range += std::to_string(laser.step_max);
  range += "] of the scanner's laser";
  if (g.step_min < laser.step_min || g.step_min > laser.step_max) {
    FailField(where, node, "step_min",
              "got " + std::to_string(g.step_min) + ", expected in " + range);
  }
  if (g.step_max < g.step_min || g.step_max > laser.step_max) {
    FailField(where, node, "step_max",
              "got " + std::to_string(g.step_max) + ", expected >= step_min and in " + range);
  }
  return g;
}

MemsScan ReadMems(const Context& where, const YAML::Node& node) {
  yaml::RequireKnownKeys(where, node,
                         {"lines", "waypoints_per_line", "waypoint_rate_hz", "fov_fraction"});
  MemsScan m;
  m.lines = Integer(where, node, "lines", 1, m.lines);
  m.waypoints_per_line = Integer(where, node, "waypoints_per_line", 2, m.waypoints_per_line);
  m.waypoint_rate_hz =
      Number(where, node, "waypoint_rate_hz", Range::kPositive, m.waypoint_rate_hz);
  if (Has(node, "fov_fraction")) {
    const Eigen::VectorXd f = yaml::Vector(where, node, "fov_fraction", 2);
    if (!InRange(f[0], Range::kFraction) || !InRange(f[1], Range::kFraction)) {
      FailField(where, node, "fov_fraction", "expected two fractions in (0, 1]");
    }
    m.fov_fraction_x = f[0];
    m.fov_fraction_y = f[1];
  }
  return m;
}

SceneScanner ReadScanner(const Context& where, const YAML::Node& node,
                         const std::filesystem::path& base_dir) {
  yaml::RequireKnownKeys(where, node, {"file", "sweeps", "galvo", "mems"});
  SceneScanner s;
  s.file = Resolve(base_dir, String(where, node, "file"));
  const std::optional<std::string> text = ReadText(s.file);
  if (!text) FailField(where, node, "file", "cannot read scanner file '" + s.file.string() + "'");
  // Read in full now: a broken scanner file should stop the scene, naming its own line.
  s.model = ParseScanner(*text, s.file.string());
  if (s.model.kind() == ScannerKind::kGalvo) {
    if (Has(node, "mems")) {
      FailField(where, node, "mems",
                "the scanner file has no top-level 'mems:', so it is a galvanometer scanner: "
                "give scanner.galvo instead");
    }
    const YAML::Node galvo = Has(node, "galvo") ? node["galvo"] : YAML::Node(YAML::NodeType::Map);
    s.galvo = ReadGalvo(yaml::Enter(where, "galvo"), galvo, s.model.galvo().laser);
  } else {
    if (Has(node, "galvo")) {
      FailField(where, node, "galvo",
                "the scanner file has a top-level 'mems:', so it is a MEMS scanner: give "
                "scanner.mems instead");
    }
    if (Has(node, "mems")) s.mems = ReadMems(yaml::Enter(where, "mems"), node["mems"]);
  }
  s.sweeps = Integer(where, node, "sweeps", 1, s.sweeps);
  return s;
}

Trajectory ReadTrajectory(const Context& where, const YAML::Node& node) {
  yaml::RequireKnownKeys(where, node, {"T_V_C", "poses"});
  Trajectory t;
  if (Has(node, "T_V_C")) t.T_V_C = yaml::Pose(where, node, "T_V_C");
  const Context list = yaml::Enter(where, "poses");
  const YAML::Node poses = yaml::Child(where, node, "poses");
  if (!poses.IsSequence() || poses.size() == 0) {
    yaml::Fail(list, poses, "expected a list of at least one {time_s, T_W_V}");
  }
  for (size_t i = 0; i < poses.size(); ++i) {
    const Context at = Item(list, i);
    yaml::RequireKnownKeys(at, poses[i], {"time_s", "T_W_V"});
    TrajectoryPose pose;
    pose.time_s = yaml::NumberOr(at, poses[i], "time_s", 0.0);
    pose.T_W_V = yaml::Pose(at, poses[i], "T_W_V");
    if (i > 0 && !(pose.time_s > t.poses.back().time_s)) {
      FailField(at, poses[i], "time_s",
                "got " + Num(pose.time_s) + " s, expected later than the pose before (" +
                    Num(t.poses.back().time_s) + " s)");
    }
    t.poses.push_back(pose);
  }
  Checked(where, node, [&] { t.Check(); });
  return t;
}

// --- effects and detector --------------------------------------------------------------------

// A stage with settings: `name: true|false`, or a mapping of its settings, on unless it says
// `on: false`. Returns whether it is on; `read` reads the settings of a mapping.
bool ReadStage(const Context& where, const YAML::Node& node, const std::string& key,
               std::initializer_list<const char*> known,
               const std::function<void(const Context&, const YAML::Node&)>& read) {
  if (!Has(node, key)) return false;
  const YAML::Node stage = node[key];
  if (stage.IsScalar()) return Boolean(where, node, key);
  const Context here = yaml::Enter(where, key);
  if (!stage.IsMap()) yaml::Fail(here, stage, "expected true, false or a mapping of settings");
  yaml::RequireKnownKeys(here, stage, known);
  read(here, stage);
  return Has(stage, "on") ? Boolean(here, stage, "on") : true;
}

// The stages of SimulationEffects with settings, each read from its key of `node` (ReadStage).
using Effects = SimulationEffects;

Effects::NavigationDrift ReadNavigationDrift(const Context& where, const YAML::Node& node) {
  Effects::NavigationDrift drift;
  drift.on =
      ReadStage(where, node, "navigation_drift",
                {"on", "position_walk_m_per_sqrt_s", "yaw_walk_rad_per_sqrt_s", "speed_scale_sigma",
                 "heading_bias_sigma_rad", "depth_sigma_m", "roll_pitch_sigma_rad"},
                [&](const Context& at, const YAML::Node& n) {
                  const auto read = [&](const char* key, double* value) {
                    *value = Number(at, n, key, Range::kNonNegative, *value);
                  };
                  read("position_walk_m_per_sqrt_s", &drift.position_walk_m_per_sqrt_s);
                  read("yaw_walk_rad_per_sqrt_s", &drift.yaw_walk_rad_per_sqrt_s);
                  read("speed_scale_sigma", &drift.speed_scale_sigma);
                  read("heading_bias_sigma_rad", &drift.heading_bias_sigma_rad);
                  read("depth_sigma_m", &drift.depth_sigma_m);
                  read("roll_pitch_sigma_rad", &drift.roll_pitch_sigma_rad);
                });
  return drift;
}

Effects::PeakNoise ReadPeakNoise(const Context& where, const YAML::Node& node) {
  Effects::PeakNoise peak_noise;
  peak_noise.on = ReadStage(
      where, node, "peak_noise", {"on", "sigma_px"}, [&](const Context& at, const YAML::Node& n) {
        peak_noise.sigma_px = Number(at, n, "sigma_px", Range::kNonNegative, peak_noise.sigma_px);
      });
  return peak_noise;
}

// The image's pixel format: mono8 or mono16, `fallback` when not given.
PixelFormat ReadPixelFormat(const Context& where, const YAML::Node& node, PixelFormat fallback) {
  if (!Has(node, "format")) return fallback;
  const std::string f = String(where, node, "format");
  if (f == "mono8") return PixelFormat::kMono8;
  if (f == "mono16") return PixelFormat::kMono16;
  FailField(where, node, "format", "got '" + f + "', expected mono8 or mono16");
}

Effects::Image ReadImage(const Context& where, const YAML::Node& node) {
  Effects::Image image;
  image.on = ReadStage(
      where, node, "image", {"on", "format", "peak_level", "blur_sigma_px"},
      [&](const Context& at, const YAML::Node& n) {
        image.format = ReadPixelFormat(at, n, image.format);
        image.peak_level = Number(at, n, "peak_level", Range::kPositive, image.peak_level);
        image.blur_sigma_px = Number(at, n, "blur_sigma_px", Range::kPositive, image.blur_sigma_px);
      });
  return image;
}

Effects::Beam ReadBeam(const Context& where, const YAML::Node& node) {
  Effects::Beam beam;
  beam.on =
      ReadStage(where, node, "beam", {"on", "diameter_m", "divergence_rad"},
                [&](const Context& at, const YAML::Node& n) {
                  beam.diameter_m = Number(at, n, "diameter_m", Range::kPositive, beam.diameter_m);
                  beam.divergence_rad =
                      Number(at, n, "divergence_rad", Range::kNonNegative, beam.divergence_rad);
                });
  return beam;
}

Effects::SensorNoise ReadSensorNoise(const Context& where, const YAML::Node& node) {
  Effects::SensorNoise noise;
  noise.on = ReadStage(
      where, node, "sensor_noise", {"on", "read_sigma", "electrons_per_level"},
      [&](const Context& at, const YAML::Node& n) {
        noise.read_sigma = Number(at, n, "read_sigma", Range::kNonNegative, noise.read_sigma);
        noise.electrons_per_level =
            Number(at, n, "electrons_per_level", Range::kPositive, noise.electrons_per_level);
      });
  return noise;
}

Effects::Speckle ReadSpeckle(const Context& where, const YAML::Node& node) {
  Effects::Speckle speckle;
  speckle.on = ReadStage(
      where, node, "speckle", {"on", "contrast"}, [&](const Context& at, const YAML::Node& n) {
        speckle.contrast = Number(at, n, "contrast", Range::kUnitInterval, speckle.contrast);
      });
  return speckle;
}

Effects::Backscatter ReadBackscatter(const Context& where, const YAML::Node& node) {
  Effects::Backscatter backscatter;
  backscatter.on = ReadStage(
      where, node, "backscatter", {"on", "level"}, [&](const Context& at, const YAML::Node& n) {
        backscatter.level = Number(at, n, "level", Range::kNonNegative, backscatter.level);
      });
  return backscatter;
}

Effects::Ambient ReadAmbient(const Context& where, const YAML::Node& node) {
  Effects::Ambient ambient;
  ambient.on = ReadStage(
      where, node, "ambient", {"on", "level"}, [&](const Context& at, const YAML::Node& n) {
        ambient.level = Number(at, n, "level", Range::kNonNegative, ambient.level);
      });
  return ambient;
}

SimulationEffects ReadEffects(const Context& where, const YAML::Node& node) {
  yaml::RequireKnownKeys(where, node,
                         {"refraction", "lens_distortion", "occlusion", "mirror_dynamics", "motion",
                          "navigation_drift", "peak_noise", "image", "beam", "sensor_noise",
                          "speckle", "attenuation", "backscatter", "ambient"});
  SimulationEffects e;
  auto flag = [&](const char* key, bool* value) {
    if (Has(node, key)) *value = Boolean(where, node, key);
  };
  flag("refraction", &e.refraction);
  flag("lens_distortion", &e.lens_distortion);
  flag("occlusion", &e.occlusion);
  flag("mirror_dynamics", &e.mirror_dynamics);
  flag("motion", &e.motion);
  flag("attenuation", &e.attenuation);
  e.navigation_drift = ReadNavigationDrift(where, node);
  e.peak_noise = ReadPeakNoise(where, node);
  e.image = ReadImage(where, node);
  e.beam = ReadBeam(where, node);
  e.sensor_noise = ReadSensorNoise(where, node);
  e.speckle = ReadSpeckle(where, node);
  e.backscatter = ReadBackscatter(where, node);
  e.ambient = ReadAmbient(where, node);
  Checked(where, node, [&] { e.Check(); });
  return e;
}

StripeDetectorOptions ReadDetector(const Context& where, const YAML::Node& node) {
  yaml::RequireKnownKeys(where, node,
                         {"method", "axis", "threshold", "window_px", "max_second_peak_ratio",
                          "min_separation_px", "steger_sigma_px"});
  StripeDetectorOptions d = Scene{}.detector;
  if (Has(node, "method")) {
    const std::string name = String(where, node, "method");
    const std::optional<StripeMethod> method = StripeMethodFromString(name);
    if (!method) {
      std::string names;
      for (const StripeMethod m : AllStripeMethods())
        names += std::string(names.empty() ? "" : ", ") + ToString(m);
      FailField(where, node, "method", "got '" + name + "', expected one of " + names);
    }
    d.method = *method;
  }
  if (Has(node, "axis")) {
    const std::string axis = String(where, node, "axis");
    if (axis == "rows") {
      d.axis = StripeAxis::kRows;
    } else if (axis == "columns") {
      d.axis = StripeAxis::kColumns;
    } else {
      FailField(where, node, "axis", "got '" + axis + "', expected rows or columns");
    }
  }
  if (Has(node, "threshold")) d.threshold = yaml::Integer(where, node, "threshold");
  if (Has(node, "window_px")) d.window_px = yaml::Integer(where, node, "window_px");
  if (Has(node, "min_separation_px")) {
    d.min_separation_px = yaml::Integer(where, node, "min_separation_px");
  }
  d.max_second_peak_ratio =
      yaml::NumberOr(where, node, "max_second_peak_ratio", d.max_second_peak_ratio);
  d.steger_sigma_px = yaml::NumberOr(where, node, "steger_sigma_px", d.steger_sigma_px);
  Checked(where, node, [&] { d.Check(); });
  return d;
}
std::uint64_t ReadSeed(const Context& where, const YAML::Node& node) {
  const YAML::Node child = yaml::Child(where, node, "seed");
  std::uint64_t seed = 0;
  if (!child.IsScalar() || child.Scalar().empty() || child.Scalar()[0] == '-' ||
      !YAML::convert<std::uint64_t>::decode(child, seed)) {
    FailField(where, node, "seed", "expected a non-negative integer");
  }
  return seed;
}

YAML::Node LoadYaml(const std::string& yaml_text, const std::string& source_name) {
  try {
    return YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw Error(source_name + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
}

}  // namespace

const char* ToString(ObjectShape shape) {
  switch (shape) {
    case ObjectShape::kPlane:
      return "plane";
    case ObjectShape::kBox:
      return "box";
    case ObjectShape::kSphere:
      return "sphere";
    case ObjectShape::kCylinder:
      return "cylinder";
    case ObjectShape::kMesh:
      return "mesh";
    case ObjectShape::kPipe:
      return "pipe";
    case ObjectShape::kElbow:
      return "elbow";
    case ObjectShape::kTee:
      return "tee";
    case ObjectShape::kFlange:
      return "flange";
    case ObjectShape::kValve:
      return "valve";
    case ObjectShape::kGauge:
      return "gauge";
  }
  return "unknown";
}

Scene ParseScene(const std::string& yaml_text, const std::string& source_name,
                 const std::filesystem::path& base_dir, SceneKind kind) {
  // Const: yaml-cpp's non-const operator[] would add the keys it looks up.
  const YAML::Node root = LoadYaml(yaml_text, source_name);
  const Context top{source_name, ""};
  yaml::CheckFormat(top, root);
  if (kind == SceneKind::kDive) {
    yaml::RequireKnownKeys(top, root,
                           {"uwscan_format", "seed", "water", "scanner", "trajectory", "effects",
                            "detector", "objects"});
  } else {
    yaml::RequireKnownKeys(
        top, root,
        {"uwscan_format", "seed", "water", "scanner", "effects", "detector", "calibration"});
  }
  Scene scene;
  scene.source = source_name;
  if (Has(root, "seed")) scene.seed = ReadSeed(top, root);
  if (Has(root, "water")) scene.water = ReadWater(yaml::Enter(top, "water"), root["water"]);
  scene.scanner =
      ReadScanner(yaml::Enter(top, "scanner"), yaml::Child(top, root, "scanner"), base_dir);
  if (Has(root, "trajectory")) {
    scene.trajectory = ReadTrajectory(yaml::Enter(top, "trajectory"), root["trajectory"]);
  } else {
    scene.trajectory.poses = {TrajectoryPose{}};  // static, world = vehicle = camera
  }
  if (Has(root, "effects"))
    scene.effects = ReadEffects(yaml::Enter(top, "effects"), root["effects"]);
  if (Has(root, "detector")) {
    scene.detector = ReadDetector(yaml::Enter(top, "detector"), root["detector"]);
  }
  if (kind == SceneKind::kDive) {
    scene.objects =
        ReadSceneObjects(yaml::Enter(top, "objects"), yaml::Child(top, root, "objects"), base_dir);
  }
  return scene;
}

Scene LoadScene(const std::filesystem::path& path) {
  const std::optional<std::string> text = ReadText(path);
  if (!text) throw Error(path.string() + ": cannot open scene file");
  const std::filesystem::path base = path.parent_path().empty() ? "." : path.parent_path();
  return ParseScene(*text, path.string(), base);
}

}  // namespace uwscan::scanner::sim