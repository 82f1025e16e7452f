#include "scanner/calibration/calibration_file.hpp"

#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <chrono>
#include <ctime>
#include <fstream>
#include <system_error>

#include "scanner/common/error.hpp"
#include "scanner/lasers/mems_scanner_model.hpp"

namespace uwscan::scanner::calibration {
namespace {

YAML::Node Load(const std::string& text) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw Error(std::string("calibration file: not valid YAML: ") + e.what());
  }
}

std::string Emit(const YAML::Node& root) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << root;
  return std::string(out.c_str()) + "\n";
}

YAML::Node Sequence(std::initializer_list<double> values) {
  YAML::Node node(YAML::NodeType::Sequence);
  for (double v : values) node.push_back(v);
  node.SetStyle(YAML::EmitterStyle::Flow);
  return node;
}

YAML::Node PoseNode(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  YAML::Node node;
  node["translation_m"] = Sequence({T.translation().x(), T.translation().y(), T.translation().z()});
  node["rotation_xyzw"] = Sequence({q.x(), q.y(), q.z(), q.w()});
  return node;
}

std::string NowUtc() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

}  // namespace

std::string WithCamera(const std::string& scanner_yaml, const PinholeCamera& c) {
  YAML::Node root = Load(scanner_yaml);
  YAML::Node camera = root["camera"];
  camera["width_px"] = c.width_px;
  camera["height_px"] = c.height_px;
  camera["fx_px"] = c.fx_px;
  camera["fy_px"] = c.fy_px;
  camera["cx_px"] = c.cx_px;
  camera["cy_px"] = c.cy_px;
  camera["distortion"] = Sequence({c.k1, c.k2, c.p1, c.p2, c.k3});
  return Emit(root);
}

std::string WithViewport(const std::string& scanner_yaml, const std::string& key,
                         const FlatViewport& v) {
  YAML::Node root = Load(scanner_yaml);
  YAML::Node node = root[key];
  node["normal"] = Sequence({v.normal.x(), v.normal.y(), v.normal.z()});
  node["distance_m"] = v.distance_m;
  node["thickness_m"] = v.thickness_m;
  node["n_air"] = v.n_air;
  node["n_glass"] = v.n_glass;
  node["n_water"] = v.n_water;
  return Emit(root);
}

std::string WithGalvoLaser(const std::string& scanner_yaml, const GalvoLaser& laser) {
  YAML::Node root = Load(scanner_yaml);
  YAML::Node node = root["laser"];
  node["T_C_L"] = PoseNode(laser.T_C_L);
  node["T_C_M"] = PoseNode(laser.T_C_M);
  node["mirror_step_rad"] = laser.mirror_step_rad;
  node["rotation_distance_m"] = laser.rotation_distance_m;
  return Emit(root);
}

std::string WithProjectionFunctions(const std::string& scanner_yaml,
                                    const ProjectionFunctions& functions) {
  YAML::Node root = Load(scanner_yaml);
  root["projection_functions"] = Load(ProjectionFunctionsToYaml(functions))["projection_functions"];
  return Emit(root);
}

std::string ScannerInMedium(const std::string& scanner_yaml, const std::optional<double>& water_index) {
  if (!water_index) return scanner_yaml;
  YAML::Node root = Load(scanner_yaml);
  for (const char* key : {"camera_viewport", "laser_viewport"}) {
    if (root[key] && root[key].IsMap()) root[key]["n_water"] = *water_index;
  }
  return Emit(root);
}

std::string WithStepRecord(const std::string& scanner_yaml, StepRecord record) {
  if (record.date_utc.empty()) record.date_utc = NowUtc();
  YAML::Node root = Load(scanner_yaml);
  YAML::Node node;
  node["dataset"] = record.dataset;
  node["date_utc"] = record.date_utc;
  node["residual_unit"] = record.residual_unit;
  node["residual_rms"] = record.residual_rms;
  node["residual_max"] = record.residual_max;
  node["observations"] = record.observations;
  node["seconds"] = record.seconds;
  YAML::Node params;
  for (const ParameterEstimate& p : record.params) {
    YAML::Node entry;
    entry["value"] = p.value;
    entry["std"] = p.std;
    entry.SetStyle(YAML::EmitterStyle::Flow);
    params[p.name] = entry;
  }
  node["params"] = params;
  root["calibration"][record.step] = node;
  return Emit(root);
}

std::vector<StepRecord> ReadStepRecords(const std::string& scanner_yaml,
                                        const std::string& source_name) {
  std::vector<StepRecord> records;
  const YAML::Node root = Load(scanner_yaml);
  if (!root["calibration"]) return records;
  try {
    for (const auto& entry : root["calibration"]) {
      StepRecord r;
      r.step = entry.first.as<std::string>();
      const YAML::Node n = entry.second;
      r.dataset = n["dataset"].as<std::string>();
      r.date_utc = n["date_utc"].as<std::string>();
      r.residual_unit = n["residual_unit"].as<std::string>();
      r.residual_rms = n["residual_rms"].as<double>();
      r.residual_max = n["residual_max"].as<double>();
      r.observations = n["observations"].as<int>();
      r.seconds = n["seconds"].as<double>();
      for (const auto& p : n["params"]) {
        r.params.push_back({p.first.as<std::string>(), p.second["value"].as<double>(),
                            p.second["std"].as<double>()});
      }
      records.push_back(r);
    }
  } catch (const YAML::Exception& e) {
    throw Error(source_name + ": calibration section malformed: " + e.what());
  }
  return records;
}

void WriteTextAtomically(const std::filesystem::path& path, const std::string& text) {
  const std::filesystem::path temp = path.string() + ".part";
  {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) throw Error(path.string() + ": cannot write (folder missing or not writable)");
    out << text;
    out.flush();
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(temp, ignored);
      throw Error(path.string() + ": write failed");
    }
  }
  std::error_code ec;
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::filesystem::remove(temp, ec);
    throw Error(path.string() + ": cannot replace the file: " + ec.message());
  }
}

}  // namespace uwscan::scanner::calibration
