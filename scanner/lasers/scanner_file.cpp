#include "scanner/lasers/scanner_file.hpp"

#include <fstream>
#include <sstream>

#include "scanner/lasers/scanner_yaml.hpp"

namespace uwscan::scanner {

// Generated at build time from data/scanners/*_default.yaml (see CMakeLists.txt).
extern const char* const kDefaultScannerYaml;
extern const char* const kDefaultMemsScannerYaml;

namespace {

GalvoScannerModel ReadGalvo(const yaml::Context& top, const YAML::Node& root) {
  yaml::RequireKnownKeys(
      top, root,
      {"uwscan_format", "camera", "camera_viewport", "laser", "laser_viewport", "calibration"});
  GalvoScannerModel m;
  m.camera.camera = yaml::ReadCamera(yaml::Enter(top, "camera"), yaml::Child(top, root, "camera"));
  m.camera.viewport = yaml::ReadViewport(yaml::Enter(top, "camera_viewport"),
                                         yaml::Child(top, root, "camera_viewport"));
  m.laser = yaml::ReadGalvoLaser(yaml::Enter(top, "laser"), yaml::Child(top, root, "laser"));
  m.laser.viewport = yaml::ReadViewport(yaml::Enter(top, "laser_viewport"),
                                        yaml::Child(top, root, "laser_viewport"));
  yaml::CheckSection(m.camera, top.source, "camera");
  yaml::CheckSection(m.laser, top.source, "laser");
  return m;
}

MemsScannerModel ReadMems(const yaml::Context& top, const YAML::Node& root) {
  yaml::RequireKnownKeys(top, root,
                         {"uwscan_format", "camera", "camera_viewport", "mems", "laser_viewport",
                          "projection_functions", "calibration"});
  MemsScannerModel m;
  m.camera.camera = yaml::ReadCamera(yaml::Enter(top, "camera"), yaml::Child(top, root, "camera"));
  m.camera.viewport = yaml::ReadViewport(yaml::Enter(top, "camera_viewport"),
                                         yaml::Child(top, root, "camera_viewport"));
  yaml::ReadMemsSection(yaml::Enter(top, "mems"), yaml::Child(top, root, "mems"), &m.laser,
                        &m.dynamics);
  m.laser.viewport = yaml::ReadViewport(yaml::Enter(top, "laser_viewport"),
                                        yaml::Child(top, root, "laser_viewport"));
  yaml::CheckSection(m.camera, top.source, "camera");
  yaml::CheckSection(m.laser, top.source, "mems");
  yaml::CheckSection(m.dynamics, top.source, "mems.dynamics");
  if (root["projection_functions"].IsDefined()) {
    m.functions = yaml::ReadProjectionFunctions(yaml::Enter(top, "projection_functions"),
                                                yaml::Child(top, root, "projection_functions"));
    m.functions_from_file = true;
    yaml::CheckSection(m.functions, top.source, "projection_functions");
  } else {
    try {
      m.FitFunctionsToLaser();
    } catch (const Error& e) {
      throw Error(top.source + ": section 'mems': fitting the projection functions: " + e.what());
    }
  }
  return m;
}

void WriteCommon(const RefractiveCamera& camera, YAML::Node* root) {
  (*root)["uwscan_format"] = 1;
  (*root)["camera"] = yaml::WriteCamera(camera.camera);
  (*root)["camera_viewport"] = yaml::WriteViewport(camera.viewport);
}

}  // namespace

Scanner ParseScanner(const std::string& yaml_text, const std::string& source_name) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw Error(source_name + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
  const yaml::Context top{source_name, ""};
  yaml::CheckFormat(top, root);
  Scanner scanner;
  if (root["mems"].IsDefined()) {
    scanner.model = ReadMems(top, root);
  } else {
    scanner.model = ReadGalvo(top, root);
  }
  if (root["calibration"].IsDefined()) {
    scanner.calibration =
        yaml::ReadStepRecords(yaml::Enter(top, "calibration"), root["calibration"]);
  }
  return scanner;
}

Scanner LoadScanner(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw Error(path.string() + ": cannot open scanner file");
  std::stringstream text;
  text << in.rdbuf();
  return ParseScanner(text.str(), path.string());
}

std::string ScannerToYaml(const Scanner& scanner, const std::string& comment) {
  scanner.Check();
  YAML::Node root;
  WriteCommon(scanner.camera(), &root);
  if (scanner.kind() == ScannerKind::kGalvo) {
    root["laser"] = yaml::WriteGalvoLaser(scanner.galvo().laser);
  } else {
    root["mems"] = yaml::WriteMemsSection(scanner.mems().laser, scanner.mems().dynamics);
  }
  root["laser_viewport"] = yaml::WriteViewport(scanner.laser_viewport());
  if (scanner.kind() == ScannerKind::kMems && scanner.mems().functions_from_file) {
    root["projection_functions"] = yaml::WriteProjectionFunctions(scanner.mems().functions);
  }
  if (!scanner.calibration.empty())
    root["calibration"] = yaml::WriteStepRecords(scanner.calibration);

  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << root;
  std::string text;
  std::istringstream lines(comment);
  for (std::string line; std::getline(lines, line);) text += "# " + line + "\n";
  return text + out.c_str() + "\n";
}

Scanner DefaultScanner(ScannerKind kind) {
  if (kind == ScannerKind::kMems)
    return ParseScanner(kDefaultMemsScannerYaml, "data/scanners/mems_default.yaml");
  return ParseScanner(kDefaultScannerYaml, "data/scanners/galvo_default.yaml");
}

}  // namespace uwscan::scanner
