#include "scanner/lasers/mems_scanner_model.hpp"

#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>

#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_yaml.hpp"

namespace uwscan::scanner {

// Generated at build time from data/scanners/mems_default.yaml (see CMakeLists.txt).
extern const char* const kDefaultMemsScannerYaml;

namespace {

Eigen::Vector2d Vector2(const yaml::Context& where, const YAML::Node& node,
                        const std::string& key) {
  return yaml::Vector(where, node, key, 2);
}

Eigen::Vector3d UnitVector3(const yaml::Context& where, const YAML::Node& node,
                            const std::string& key) {
  const Eigen::Vector3d v = yaml::Vector3(where, node, key);
  if (std::abs(v.norm() - 1.0) > 1e-6) {
    yaml::Fail(yaml::Enter(where, key), node[key], "expected a unit vector");
  }
  return v.normalized();
}

MirrorDynamicsOptions ReadDynamics(const yaml::Context& where, const YAML::Node& node) {
  yaml::RequireKnownKeys(where, node,
                         {"resonance_hz", "damping_ratio", "lpf_cutoff_hz", "lpf_order",
                          "waypoint_rate_hz", "settle_s", "sample_rate_hz"});
  MirrorDynamicsOptions d;
  d.resonance_hz = yaml::Number(where, node, "resonance_hz");
  d.damping_ratio = yaml::Number(where, node, "damping_ratio");
  d.lpf_cutoff_hz = yaml::Number(where, node, "lpf_cutoff_hz");
  d.lpf_order = yaml::Integer(where, node, "lpf_order");
  d.waypoint_rate_hz = yaml::Number(where, node, "waypoint_rate_hz");
  d.settle_s = yaml::Number(where, node, "settle_s");
  d.sample_rate_hz = yaml::Number(where, node, "sample_rate_hz");
  return d;
}

// The `mems:` section: the laser (without its viewport) and the mirror dynamics.
void ReadMems(const yaml::Context& where, const YAML::Node& node, MemsLaser* laser,
              MirrorDynamicsOptions* dynamics) {
  yaml::RequireKnownKeys(where, node,
                         {"emitter", "T_C_M", "max_volts", "max_tilt_rad", "saturation", "T_C_Lens",
                          "lens_gain", "dynamics"});
  const yaml::Context emitter_where = yaml::Enter(where, "emitter");
  const YAML::Node emitter = yaml::Child(where, node, "emitter");
  yaml::RequireKnownKeys(emitter_where, emitter, {"origin_m", "direction"});
  laser->emitter_origin_C = yaml::Vector3(emitter_where, emitter, "origin_m");
  laser->emitter_direction_C = UnitVector3(emitter_where, emitter, "direction");
  laser->T_C_M = yaml::Pose(where, node, "T_C_M");
  laser->max_volts = yaml::Number(where, node, "max_volts");
  laser->max_tilt_rad = Vector2(where, node, "max_tilt_rad");
  laser->saturation = Vector2(where, node, "saturation");
  laser->T_C_Lens = yaml::Pose(where, node, "T_C_Lens");
  laser->lens_gain = yaml::Number(where, node, "lens_gain");
  *dynamics = ReadDynamics(yaml::Enter(where, "dynamics"), yaml::Child(where, node, "dynamics"));
}

// Every value Polynomial2d's constructor would reject is caught here first, with its line.
Polynomial2d ReadPolynomial(const yaml::Context& where, const YAML::Node& node) {
  yaml::RequireKnownKeys(where, node, {"degree", "center", "scale", "coefficients"});
  const int degree = yaml::Integer(where, node, "degree");
  if (degree < 0 || degree > Polynomial2d::kMaxDegree) {
    yaml::Fail(yaml::Enter(where, "degree"), node["degree"],
               "expected a degree in [0, " + std::to_string(Polynomial2d::kMaxDegree) + "]");
  }
  const Eigen::Vector2d center = Vector2(where, node, "center");
  const Eigen::Vector2d scale = Vector2(where, node, "scale");
  if (!(scale.minCoeff() > 0.0)) {
    yaml::Fail(yaml::Enter(where, "scale"), node["scale"], "expected positive half-ranges");
  }
  const Eigen::VectorXd coefficients =
      yaml::Vector(where, node, "coefficients", Polynomial2d::TermCount(degree));
  return Polynomial2d(degree, center, scale, coefficients);
}

ProjectionFunctions ReadProjectionFunctions(const yaml::Context& where, const YAML::Node& node) {
  yaml::RequireKnownKeys(where, node,
                         {"T_C_P", "volts_min", "volts_max", "f1", "f2", "f3", "f4", "f5", "f6"});
  ProjectionFunctions f;
  f.T_C_P = yaml::Pose(where, node, "T_C_P");
  f.volts_min = Vector2(where, node, "volts_min");
  f.volts_max = Vector2(where, node, "volts_max");
  Polynomial2d* const targets[6] = {&f.f1, &f.f2, &f.f3, &f.f4, &f.f5, &f.f6};
  const char* const names[6] = {"f1", "f2", "f3", "f4", "f5", "f6"};
  for (int i = 0; i < 6; ++i) {
    *targets[i] = ReadPolynomial(yaml::Enter(where, names[i]), yaml::Child(where, node, names[i]));
  }
  return f;
}

void WriteNumbers(std::ostream& out, const double* values, Eigen::Index count) {
  out << '[';
  for (Eigen::Index i = 0; i < count; ++i) out << (i == 0 ? "" : ", ") << values[i];
  out << ']';
}

}  // namespace

void MemsScannerModel::Check() const {
  camera.Check();
  laser.Check();
  dynamics.Check();
  functions.Check();
}

MemsScannerModel ParseMemsScannerModel(const std::string& yaml_text,
                                       const std::string& source_name) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw Error(source_name + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
  const yaml::Context top{source_name, ""};
  yaml::CheckFormat(top, root);
  yaml::RequireKnownKeys(top, root,
                         {"uwscan_format", "camera", "camera_viewport", "mems", "laser_viewport",
                          "projection_functions", "calibration"});
  MemsScannerModel m;
  m.camera.camera = yaml::ReadCamera(yaml::Enter(top, "camera"), yaml::Child(top, root, "camera"));
  m.camera.viewport = yaml::ReadViewport(yaml::Enter(top, "camera_viewport"),
                                         yaml::Child(top, root, "camera_viewport"));
  ReadMems(yaml::Enter(top, "mems"), yaml::Child(top, root, "mems"), &m.laser, &m.dynamics);
  m.laser.viewport = yaml::ReadViewport(yaml::Enter(top, "laser_viewport"),
                                        yaml::Child(top, root, "laser_viewport"));
  yaml::CheckSection(m.camera, source_name, "camera");
  yaml::CheckSection(m.laser, source_name, "mems");
  yaml::CheckSection(m.dynamics, source_name, "mems.dynamics");
  if (root["projection_functions"].IsDefined()) {
    m.functions = ReadProjectionFunctions(yaml::Enter(top, "projection_functions"),
                                          yaml::Child(top, root, "projection_functions"));
    yaml::CheckSection(m.functions, source_name, "projection_functions");
  } else {
    try {
      m.functions = SampleProjectionFunctions(m.laser);
    } catch (const Error& e) {
      throw Error(source_name + ": section 'mems': fitting the projection functions: " + e.what());
    }
  }
  return m;
}

MemsScannerModel LoadMemsScannerModel(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw Error(path.string() + ": cannot open MEMS scanner file");
  std::stringstream text;
  text << in.rdbuf();
  return ParseMemsScannerModel(text.str(), path.string());
}

MemsScannerModel DefaultMemsScannerModel() {
  return ParseMemsScannerModel(kDefaultMemsScannerYaml, "data/scanners/mems_default.yaml");
}

std::string ProjectionFunctionsToYaml(const ProjectionFunctions& functions) {
  functions.Check();
  std::ostringstream out;
  out << std::setprecision(std::numeric_limits<double>::max_digits10);
  const Eigen::Quaterniond q(functions.T_C_P.linear());
  const Eigen::Vector3d& t = functions.T_C_P.translation();
  const double quaternion[4] = {q.x(), q.y(), q.z(), q.w()};
  out << "projection_functions:\n  T_C_P:\n    translation_m: ";
  WriteNumbers(out, t.data(), 3);
  out << "\n    rotation_xyzw: ";
  WriteNumbers(out, quaternion, 4);
  out << "\n  volts_min: ";
  WriteNumbers(out, functions.volts_min.data(), 2);
  out << "\n  volts_max: ";
  WriteNumbers(out, functions.volts_max.data(), 2);
  out << '\n';
  const Polynomial2d* const polynomials[6] = {&functions.f1, &functions.f2, &functions.f3,
                                              &functions.f4, &functions.f5, &functions.f6};
  for (int i = 0; i < 6; ++i) {
    const Polynomial2d& f = *polynomials[i];
    out << "  f" << i + 1 << ":\n    degree: " << f.degree() << "\n    center: ";
    WriteNumbers(out, f.center().data(), 2);
    out << "\n    scale: ";
    WriteNumbers(out, f.scale().data(), 2);
    out << "\n    coefficients: ";
    WriteNumbers(out, f.coefficients().data(), f.coefficients().size());
    out << '\n';
  }
  return out.str();
}

}  // namespace uwscan::scanner
