#include "scanner/calibration/calibration_scene.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <string>

#include "scanner/calibration/calibration_dataset.hpp"
#include "scanner/calibration/calibration_yaml.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"

namespace uwscan::scanner::calibration {
namespace {

namespace fs = std::filesystem;
using namespace calibration_yaml;
using namespace sim::scene_yaml;

Eigen::Vector2d Pair(const Context& where, const YAML::Node& node, const std::string& key) {
  const Eigen::VectorXd v = yaml::Vector(where, node, key, 2);
  return Eigen::Vector2d(v[0], v[1]);
}

void ReadInitialScanner(const Context& where, const YAML::Node& node, const fs::path& base_dir,
                        CalibrationScene* cs) {
  if (node.IsScalar()) {
    cs->initial_scanner = Resolve(base_dir, node.Scalar());
  } else {
    yaml::RequireKnownKeys(where, node, {"file", "true_sections"});
    cs->initial_scanner = Resolve(base_dir, String(where, node, "file"));
    if (Has(node, "true_sections")) {
      const YAML::Node list = node["true_sections"];
      const Context at = yaml::Enter(where, "true_sections");
      if (!list.IsSequence()) yaml::Fail(at, list, "expected a list of scanner file sections");
      const std::vector<std::string> sections = ScannerSections(cs->scene.scanner.model.kind());
      for (size_t i = 0; i < list.size(); ++i) {
        const std::string section = list[i].IsScalar() ? list[i].Scalar() : std::string();
        // Fitted projection functions are not a section of the file: the truth gives none.
        const bool fitted_functions = section == "projection_functions" &&
                                      !cs->scene.scanner.model.mems().functions_from_file;
        if (std::find(sections.begin(), sections.end(), section) == sections.end() ||
            fitted_functions) {
          yaml::Fail(Item(at, i), list[i],
                     "expected a top-level section of the true scanner file " +
                         cs->scene.scanner.file.string() + ", got '" + section + "'");
        }
        cs->initial_true_sections.push_back(section);
      }
    }
  }
  if (!fs::is_regular_file(*cs->initial_scanner)) {
    yaml::Fail(where, node, "initial scanner file not found: " + cs->initial_scanner->string());
  }
}

TargetRenderOptions ReadRender(const Context& where, const YAML::Node& node, bool mono16) {
  yaml::RequireKnownKeys(
      where, node, {"supersampling", "blur_sigma_px", "white_level", "black_level", "noise_sigma"});
  TargetRenderOptions r;
  const double scale = mono16 ? 257.0 : 1.0;  // 8-bit units -> 16-bit
  r.supersampling = Integer(where, node, "supersampling", 1, r.supersampling);
  r.blur_sigma_px = Number(where, node, "blur_sigma_px", Range::kNonNegative, r.blur_sigma_px);
  r.white_level = scale * Number(where, node, "white_level", Range::kPositive, r.white_level);
  r.black_level = scale * Number(where, node, "black_level", Range::kNonNegative, r.black_level);
  r.noise_sigma = scale * Number(where, node, "noise_sigma", Range::kNonNegative, r.noise_sigma);
  r.format = mono16 ? PixelFormat::kMono16 : PixelFormat::kMono8;
  Checked(where, node, [&] { r.Check(); });
  return r;
}

// One of CalibrationSteps().
std::string ReadStep(const Context& where, const YAML::Node& node) {
  std::string step = String(where, node, "step");
  const std::vector<std::string>& steps = CalibrationSteps();
  if (std::find(steps.begin(), steps.end(), step) == steps.end()) {
    std::string names;
    for (const std::string& s : steps) names += (names.empty() ? "" : ", ") + s;
    FailField(where, node, "step", "got '" + step + "', expected one of " + names);
  }
  return step;
}

// What a step's images are: pattern views, laser stripes on planes, or laser dots on planes.
struct StepKind {
  bool views = false;
  bool stripes = false;
  bool dots = false;
};

StepKind KindOf(const std::string& step) {
  return StepKind{step == "intrinsics" || step == "viewport",
                  step == "laser" || step == "laser_viewport", step == "mems"};
}

// A field the step ignores is most likely a mistake (copied from another step's scene).
void RejectOtherStepsFields(const Context& where, const YAML::Node& node, const std::string& step,
                            const StepKind& kind) {
  auto only = [&](const char* key, bool used, const char* which) {
    if (Has(node, key) && !used) {
      FailField(where, node, key,
                std::string("not used by a ") + step + " step (only " + which + ")");
    }
  };
  only("views", kind.views, "intrinsics and viewport");
  only("planes", !kind.views, "laser, laser_viewport and mems");
  only("mirror_steps", kind.stripes, "laser and laser_viewport");
  only("volts_grid", kind.dots, "mems");
  only("volts_fraction", kind.dots, "mems");
}

// Stripes need a galvanometer scanner, dots a MEMS one.
void CheckScannerFitsStep(const Context& where, const YAML::Node& node, const CalibrationScene& cs,
                          const StepKind& kind) {
  const bool mems_scanner = cs.scene.scanner.model.kind() == ScannerKind::kMems;
  if ((kind.stripes && mems_scanner) || (kind.dots && !mems_scanner)) {
    FailField(where, node, "step",
              "a " + cs.step + " step needs a " + (kind.stripes ? "galvanometer" : "MEMS") +
                  " scanner; " + cs.scene.scanner.file.string() + " is a " +
                  (mems_scanner ? "MEMS" : "galvanometer") + " scanner");
  }
}

void ReadBoard(const Context& where, const YAML::Node& node, CalibrationScene* cs) {
  cs->pattern = ReadPattern(yaml::Enter(where, "pattern"), yaml::Child(where, node, "pattern"));
  if (Has(node, "board_size_m")) {
    cs->board_size_m = Pair(where, node, "board_size_m");
    Checked(yaml::Enter(where, "board_size_m"), node["board_size_m"],
            [&] { BoardOf(cs->pattern, cs->board_size_m); });
  }
  cs->board_reflectance =
      Number(where, node, "board_reflectance", Range::kFraction, cs->board_reflectance);
}

// How many board poses, and how they are drawn: depth, tilt, roll.
void ReadPoses(const Context& where, const YAML::Node& node, CalibrationScene* cs) {
  cs->views = Integer(where, node, "views", 3, cs->views);
  cs->planes = Integer(where, node, "planes", 2, cs->planes);
  if (Has(node, "distance_m")) {
    cs->distance_m = Pair(where, node, "distance_m");
    if (!(cs->distance_m.x() > 0.0 && cs->distance_m.y() >= cs->distance_m.x())) {
      FailField(where, node, "distance_m", "expected [min, max] with 0 < min <= max, metres");
    }
  }
  cs->max_tilt_rad = Number(where, node, "max_tilt_rad", Range::kNonNegative, cs->max_tilt_rad);
  if (cs->max_tilt_rad > 1.3) FailField(where, node, "max_tilt_rad", "expected <= 1.3 rad");
  cs->max_roll_rad = Number(where, node, "max_roll_rad", Range::kNonNegative, cs->max_roll_rad);
  if (cs->max_roll_rad > M_PI) FailField(where, node, "max_roll_rad", "expected <= pi rad");
}

// Distinct integer steps within the laser's range, at least 2.
std::vector<int> ReadMirrorSteps(const Context& where, const YAML::Node& node,
                                 const GalvoLaser& laser) {
  const Context at = yaml::Enter(where, "mirror_steps");
  const YAML::Node list = yaml::Child(where, node, "mirror_steps");
  if (!list.IsSequence()) yaml::Fail(at, list, "expected a list of mirror steps");
  std::vector<int> mirror_steps;
  std::set<int> seen;
  for (size_t i = 0; i < list.size(); ++i) {
    int step = 0;
    if (!list[i].IsScalar() || !YAML::convert<int>::decode(list[i], step)) {
      yaml::Fail(Item(at, i), list[i], "expected an integer mirror step");
    }
    if (step < laser.step_min || step > laser.step_max) {
      yaml::Fail(Item(at, i), list[i],
                 "mirror step " + std::to_string(step) + " outside the laser's range [" +
                     std::to_string(laser.step_min) + ", " + std::to_string(laser.step_max) + "]");
    }
    if (!seen.insert(step).second) {
      yaml::Fail(Item(at, i), list[i], "mirror step " + std::to_string(step) + " given twice");
    }
    mirror_steps.push_back(step);
  }
  if (mirror_steps.size() < 2) yaml::Fail(at, list, "expected at least 2 mirror steps");
  return mirror_steps;
}

void ReadVoltsGrid(const Context& where, const YAML::Node& node, CalibrationScene* cs) {
  if (Has(node, "volts_grid")) {
    const Eigen::VectorXd grid = yaml::Vector(where, node, "volts_grid", 2);
    if (grid[0] < 1 || grid[1] < 1 || grid[0] != std::floor(grid[0]) ||
        grid[1] != std::floor(grid[1]) || grid[0] * grid[1] > 100000) {
      FailField(where, node, "volts_grid", "expected [a, b], whole numbers >= 1");
    }
    cs->volts_grid = Eigen::Vector2i(static_cast<int>(grid[0]), static_cast<int>(grid[1]));
  }
  cs->volts_fraction = Number(where, node, "volts_fraction", Range::kFraction, cs->volts_fraction);
}

void ReadSection(const Context& where, const YAML::Node& node, const fs::path& base_dir,
                 CalibrationScene* cs) {
  yaml::RequireKnownKeys(where, node,
                         {"step", "pattern", "board_size_m", "board_reflectance", "initial_scanner",
                          "views", "planes", "distance_m", "max_tilt_rad", "max_roll_rad",
                          "mirror_steps", "volts_grid", "volts_fraction", "image_scale", "render"});
  cs->step = ReadStep(where, node);
  const StepKind kind = KindOf(cs->step);
  RejectOtherStepsFields(where, node, cs->step, kind);
  CheckScannerFitsStep(where, node, *cs, kind);
  ReadBoard(where, node, cs);
  if (Has(node, "initial_scanner")) {
    ReadInitialScanner(yaml::Enter(where, "initial_scanner"), node["initial_scanner"], base_dir,
                       cs);
  }
  ReadPoses(where, node, cs);
  cs->image_scale = Number(where, node, "image_scale", Range::kFraction, cs->image_scale);
  cs->render = ReadRender(yaml::Enter(where, "render"),
                          Has(node, "render") ? node["render"] : YAML::Node(YAML::NodeType::Map),
                          cs->scene.effects.image.format == PixelFormat::kMono16);
  if (kind.stripes) {
    cs->mirror_steps = ReadMirrorSteps(where, node, cs->scene.scanner.model.galvo().laser);
  }
  if (kind.dots) ReadVoltsGrid(where, node, cs);
}

}  // namespace

void CalibrationScene::Check() const {
  // Named by the scene file: "calib_laser.yaml: calibration.views: expected >= 3, got 2".
  const OptionChecks check(scene.source + ": calibration");
  const auto nested = [&](const std::string& field, const std::function<void()>& nested_check) {
    try {
      nested_check();
    } catch (const Error& e) {
      throw Error(scene.source + ": calibration." + field + ": " + e.what());
    }
  };
  const std::vector<std::string>& steps = CalibrationSteps();
  if (std::find(steps.begin(), steps.end(), step) == steps.end()) {
    std::string names;
    for (const std::string& s : steps) names += (names.empty() ? "" : ", ") + s;
    check.Fail("step", "one of " + names, OptionQuotedText(step));
  }
  const bool stripes = step == "laser" || step == "laser_viewport";
  const bool mems_scanner = scene.scanner.model.kind() == ScannerKind::kMems;
  check.Require(!(stripes && mems_scanner) && !(step == "mems" && !mems_scanner), "step",
                std::string("a step the ") + (mems_scanner ? "MEMS" : "galvanometer") +
                    " scanner " + scene.scanner.file.string() + " can simulate",
                OptionQuotedText(step));
  nested("pattern", [&] { pattern.Check(); });
  nested("board_size_m", [&] { BoardOf(pattern, board_size_m); });
  nested("render", [&] { render.Check(); });
  check.InRange("board_reflectance", board_reflectance, 0.0, 1.0, Interval::kOpenLow);
  check.AtLeast("views", views, 3);
  check.AtLeast("planes", planes, 2);
  check.Require(distance_m.x() > 0.0 && distance_m.y() >= distance_m.x(), "distance_m",
                "[min, max] with 0 < min <= max, metres",
                OptionPairText(distance_m.x(), distance_m.y()));
  check.InRange("max_tilt_rad", max_tilt_rad, 0.0, 1.3, Interval::kClosed, "rad");
  check.Require(max_roll_rad >= 0.0 && max_roll_rad <= M_PI, "max_roll_rad", "in [0, pi] rad",
                max_roll_rad);
  check.InRange("image_scale", image_scale, 0.0, 1.0, Interval::kOpenLow);
  if (stripes) {
    const GalvoLaser& laser = scene.scanner.model.galvo().laser;
    const std::set<int> distinct(mirror_steps.begin(), mirror_steps.end());
    check.Require(distinct.size() == mirror_steps.size() && distinct.size() >= 2, "mirror_steps",
                  "at least 2 mirror steps, each once",
                  std::to_string(mirror_steps.size()) + " steps, " +
                      std::to_string(distinct.size()) + " distinct");
    check.Require(*distinct.begin() >= laser.step_min && *distinct.rbegin() <= laser.step_max,
                  "mirror_steps",
                  "steps in the laser's range [" + std::to_string(laser.step_min) + ", " +
                      std::to_string(laser.step_max) + "]",
                  "steps from " + std::to_string(*distinct.begin()) + " to " +
                      std::to_string(*distinct.rbegin()));
  }
  if (step == "mems") {
    check.Require(volts_grid.minCoeff() >= 1, "volts_grid", "[a, b] >= 1",
                  OptionPairText(volts_grid.x(), volts_grid.y()));
    check.InRange("volts_fraction", volts_fraction, 0.0, 1.0, Interval::kOpenLow);
  }
}

CalibrationScene ParseCalibrationScene(const std::string& yaml_text, const std::string& source,
                                       const fs::path& base_dir) {
  const YAML::Node root = LoadYaml(yaml_text, source);
  const Context top{source, ""};
  yaml::CheckFormat(top, root);
  if (Has(root, "objects")) {
    FailField(top, root, "objects",
              "a calibration scene has no objects: the board, posed by the simulation, is the "
              "only one");
  }
  if (Has(root, "trajectory")) {
    FailField(top, root, "trajectory",
              "a calibration scene has no trajectory: the camera stays at the world origin and "
              "the board moves");
  }
  const YAML::Node section = yaml::Child(top, root, "calibration");
  CalibrationScene cs;
  cs.scene = sim::ParseScene(yaml_text, source, base_dir, sim::SceneKind::kCalibration);
  ReadSection(yaml::Enter(top, "calibration"), section, base_dir, &cs);
  cs.Check();
  return cs;
}

CalibrationScene LoadCalibrationScene(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw Error(path.string() + ": cannot open calibration scene");
  std::stringstream text;
  text << in.rdbuf();
  const fs::path base = path.parent_path().empty() ? "." : path.parent_path();
  return ParseCalibrationScene(text.str(), path.string(), base);
}

}  // namespace uwscan::scanner::calibration
