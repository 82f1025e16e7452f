#include "scanner/lasers/scanner_model.hpp"

#include <fstream>
#include <sstream>

#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_yaml.hpp"

namespace uwscan::scanner {

// Generated at build time from data/scanners/galvo_default.yaml (see CMakeLists.txt).
extern const char* const kDefaultScannerYaml;

namespace {

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
                         {"uwscan_format", "camera", "camera_viewport", "laser", "laser_viewport",
                          "calibration"});  // calibration: the record of how it was calibrated
  ScannerModel m;
  m.camera.camera = yaml::ReadCamera(yaml::Enter(top, "camera"), yaml::Child(top, root, "camera"));
  m.camera.viewport = yaml::ReadViewport(yaml::Enter(top, "camera_viewport"),
                                         yaml::Child(top, root, "camera_viewport"));
  m.laser = ReadLaser(yaml::Enter(top, "laser"), yaml::Child(top, root, "laser"));
  m.laser.viewport = yaml::ReadViewport(yaml::Enter(top, "laser_viewport"),
                                        yaml::Child(top, root, "laser_viewport"));
  yaml::CheckSection(m.camera, source_name, "camera");
  yaml::CheckSection(m.laser, source_name, "laser");
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
