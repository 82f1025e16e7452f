#include "scanner/scanner_model.hpp"

#include <fstream>
#include <sstream>

#include "scanner/error.hpp"
#include "scanner/yaml_fields.hpp"

namespace uwscan::scanner {

// Generated at build time from data/scanners/galvo_default.yaml (see CMakeLists.txt).
extern const char* const kDefaultScannerYaml;

namespace {

PinholeCamera ReadCamera(const yaml::Context& where, const YAML::Node& node) {
  yaml::RequireKnownKeys(where, node,
                         {"width_px", "height_px", "fx_px", "fy_px", "cx_px", "cy_px", "distortion"});
  PinholeCamera c;
  c.width_px = yaml::Integer(where, node, "width_px");
  c.height_px = yaml::Integer(where, node, "height_px");
  c.fx_px = yaml::Number(where, node, "fx_px");
  c.fy_px = yaml::Number(where, node, "fy_px");
  c.cx_px = yaml::Number(where, node, "cx_px");
  c.cy_px = yaml::Number(where, node, "cy_px");
  const Eigen::VectorXd d = yaml::Vector(where, node, "distortion", 5);
  c.k1 = d[0], c.k2 = d[1], c.p1 = d[2], c.p2 = d[3], c.k3 = d[4];
  return c;
}

FlatViewport ReadViewport(const yaml::Context& where, const YAML::Node& node) {
  yaml::RequireKnownKeys(where, node,
                         {"normal", "distance_m", "thickness_m", "n_air", "n_glass", "n_water"});
  FlatViewport v;
  v.normal = yaml::Vector3(where, node, "normal");
  if (std::abs(v.normal.norm() - 1.0) > 1e-6) {
    yaml::Fail(yaml::Enter(where, "normal"), node["normal"], "expected a unit vector");
  }
  v.normal.normalize();
  v.distance_m = yaml::Number(where, node, "distance_m");
  v.thickness_m = yaml::Number(where, node, "thickness_m");
  v.n_air = yaml::NumberOr(where, node, "n_air", v.n_air);
  v.n_glass = yaml::NumberOr(where, node, "n_glass", v.n_glass);
  v.n_water = yaml::NumberOr(where, node, "n_water", v.n_water);
  return v;
}

GalvoLaser ReadLaser(const yaml::Context& where, const YAML::Node& node) {
  yaml::RequireKnownKeys(where, node,
                         {"T_C_L", "T_C_M", "mirror_step_rad", "rotation_distance_m",
                          "aperture_rad", "step_min", "step_max"});
  GalvoLaser l;
  l.T_C_L = yaml::Pose(where, node, "T_C_L");
  l.T_C_M = yaml::Pose(where, node, "T_C_M");
  l.mirror_step_rad = yaml::Number(where, node, "mirror_step_rad");
  l.rotation_distance_m = yaml::Number(where, node, "rotation_distance_m");
  l.aperture_rad = yaml::Number(where, node, "aperture_rad");
  l.step_min = yaml::Integer(where, node, "step_min");
  l.step_max = yaml::Integer(where, node, "step_max");
  return l;
}

// Runs a Check() and prefixes its message with the source and section it came from.
template <typename T>
void CheckSection(const T& value, const std::string& source, const std::string& section) {
  try {
    value.Check();
  } catch (const Error& e) {
    throw Error(source + ": section '" + section + "': " + e.what());
  }
}

}  // namespace

void ScannerModel::Check() const {
  camera.Check();
  laser.Check();
}

ScannerModel ParseScannerModel(const std::string& yaml_text, const std::string& source_name) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw Error(source_name + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
  const yaml::Context top{source_name, ""};
  yaml::CheckFormat(top, root);
  yaml::RequireKnownKeys(top, root,
                         {"uwscan_format", "camera", "camera_viewport", "laser", "laser_viewport"});
  ScannerModel m;
  m.camera.camera = ReadCamera(yaml::Enter(top, "camera"), yaml::Child(top, root, "camera"));
  m.camera.viewport = ReadViewport(yaml::Enter(top, "camera_viewport"),
                                   yaml::Child(top, root, "camera_viewport"));
  m.laser = ReadLaser(yaml::Enter(top, "laser"), yaml::Child(top, root, "laser"));
  m.laser.viewport = ReadViewport(yaml::Enter(top, "laser_viewport"),
                                  yaml::Child(top, root, "laser_viewport"));
  CheckSection(m.camera, source_name, "camera");
  CheckSection(m.laser, source_name, "laser");
  return m;
}

ScannerModel LoadScannerModel(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw Error(path.string() + ": cannot open scanner file");
  std::stringstream text;
  text << in.rdbuf();
  return ParseScannerModel(text.str(), path.string());
}

ScannerModel DefaultScannerModel() {
  return ParseScannerModel(kDefaultScannerYaml, "data/scanners/galvo_default.yaml");
}

}  // namespace uwscan::scanner
