#include "scanner/lasers/scanner_yaml.hpp"

#include <cmath>

namespace uwscan::scanner::yaml {
namespace {

YAML::Node Numbers(const double* values, Eigen::Index count) {
  YAML::Node node(YAML::NodeType::Sequence);
  for (Eigen::Index i = 0; i < count; ++i) node.push_back(values[i]);
  node.SetStyle(YAML::EmitterStyle::Flow);
  return node;
}

template <typename Vector>
YAML::Node Numbers(const Vector& v) {
  const Eigen::Ref<const Eigen::VectorXd> values = v;
  return Numbers(values.data(), values.size());
}

Eigen::Vector2d Vector2(const Context& where, const YAML::Node& node, const std::string& key) {
  return Vector(where, node, key, 2);
}

Eigen::Vector3d UnitVector3(const Context& where, const YAML::Node& node, const std::string& key) {
  const Eigen::Vector3d v = Vector3(where, node, key);
  if (std::abs(v.norm() - 1.0) > 1e-6) Fail(Enter(where, key), node[key], "expected a unit vector");
  return v.normalized();
}

MirrorDynamicsOptions ReadDynamics(const Context& where, const YAML::Node& node) {
  RequireKnownKeys(where, node,
                   {"resonance_hz", "damping_ratio", "lpf_cutoff_hz", "lpf_order",
                    "waypoint_rate_hz", "settle_s", "sample_rate_hz"});
  MirrorDynamicsOptions d;
  d.resonance_hz = Number(where, node, "resonance_hz");
  d.damping_ratio = Number(where, node, "damping_ratio");
  d.lpf_cutoff_hz = Number(where, node, "lpf_cutoff_hz");
  d.lpf_order = Integer(where, node, "lpf_order");
  d.waypoint_rate_hz = Number(where, node, "waypoint_rate_hz");
  d.settle_s = Number(where, node, "settle_s");
  d.sample_rate_hz = Number(where, node, "sample_rate_hz");
  return d;
}

YAML::Node WriteDynamics(const MirrorDynamicsOptions& d) {
  YAML::Node node;
  node["resonance_hz"] = d.resonance_hz;
  node["damping_ratio"] = d.damping_ratio;
  node["lpf_cutoff_hz"] = d.lpf_cutoff_hz;
  node["lpf_order"] = d.lpf_order;
  node["waypoint_rate_hz"] = d.waypoint_rate_hz;
  node["settle_s"] = d.settle_s;
  node["sample_rate_hz"] = d.sample_rate_hz;
  return node;
}

// Every value Polynomial2d's constructor would reject is caught here first, with its line.
Polynomial2d ReadPolynomial(const Context& where, const YAML::Node& node) {
  RequireKnownKeys(where, node, {"degree", "center", "scale", "coefficients"});
  const int degree = Integer(where, node, "degree");
  if (degree < 0 || degree > Polynomial2d::kMaxDegree) {
    Fail(Enter(where, "degree"), node["degree"],
         "expected a degree in [0, " + std::to_string(Polynomial2d::kMaxDegree) + "]");
  }
  const Eigen::Vector2d center = Vector2(where, node, "center");
  const Eigen::Vector2d scale = Vector2(where, node, "scale");
  if (!(scale.minCoeff() > 0.0))
    Fail(Enter(where, "scale"), node["scale"], "expected positive half-ranges");
  const Eigen::VectorXd coefficients =
      Vector(where, node, "coefficients", Polynomial2d::TermCount(degree));
  return Polynomial2d(degree, center, scale, coefficients);
}

YAML::Node WritePolynomial(const Polynomial2d& f) {
  YAML::Node node;
  node["degree"] = f.degree();
  node["center"] = Numbers(f.center());
  node["scale"] = Numbers(f.scale());
  node["coefficients"] = Numbers(f.coefficients());
  return node;
}

constexpr const char* kFunctionNames[6] = {"f1", "f2", "f3", "f4", "f5", "f6"};

}  // namespace

YAML::Node WritePose(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  const double quaternion[4] = {q.x(), q.y(), q.z(), q.w()};
  YAML::Node node;
  node["translation_m"] = Numbers(T.translation());
  node["rotation_xyzw"] = Numbers(quaternion, 4);
  return node;
}

PinholeCamera ReadCamera(const Context& where, const YAML::Node& node) {
  RequireKnownKeys(where, node,
                   {"width_px", "height_px", "fx_px", "fy_px", "cx_px", "cy_px", "distortion"});
  PinholeCamera c;
  c.width_px = Integer(where, node, "width_px");
  c.height_px = Integer(where, node, "height_px");
  c.fx_px = Number(where, node, "fx_px");
  c.fy_px = Number(where, node, "fy_px");
  c.cx_px = Number(where, node, "cx_px");
  c.cy_px = Number(where, node, "cy_px");
  const Eigen::VectorXd d = Vector(where, node, "distortion", 5);
  c.k1 = d[0], c.k2 = d[1], c.p1 = d[2], c.p2 = d[3], c.k3 = d[4];
  return c;
}

YAML::Node WriteCamera(const PinholeCamera& c) {
  const double distortion[5] = {c.k1, c.k2, c.p1, c.p2, c.k3};
  YAML::Node node;
  node["width_px"] = c.width_px;
  node["height_px"] = c.height_px;
  node["fx_px"] = c.fx_px;
  node["fy_px"] = c.fy_px;
  node["cx_px"] = c.cx_px;
  node["cy_px"] = c.cy_px;
  node["distortion"] = Numbers(distortion, 5);
  return node;
}

FlatViewport ReadViewport(const Context& where, const YAML::Node& node) {
  RequireKnownKeys(where, node,
                   {"normal", "distance_m", "thickness_m", "n_air", "n_glass", "n_water"});
  FlatViewport v;
  v.normal = UnitVector3(where, node, "normal");
  v.distance_m = Number(where, node, "distance_m");
  v.thickness_m = Number(where, node, "thickness_m");
  v.n_air = NumberOr(where, node, "n_air", v.n_air);
  v.n_glass = NumberOr(where, node, "n_glass", v.n_glass);
  v.n_water = NumberOr(where, node, "n_water", v.n_water);
  return v;
}

YAML::Node WriteViewport(const FlatViewport& v) {
  YAML::Node node;
  node["normal"] = Numbers(v.normal);
  node["distance_m"] = v.distance_m;
  node["thickness_m"] = v.thickness_m;
  node["n_air"] = v.n_air;
  node["n_glass"] = v.n_glass;
  node["n_water"] = v.n_water;
  return node;
}

GalvoLaser ReadGalvoLaser(const Context& where, const YAML::Node& node) {
  RequireKnownKeys(where, node,
                   {"T_C_L", "T_C_M", "mirror_step_rad", "rotation_distance_m", "aperture_rad",
                    "step_min", "step_max"});
  GalvoLaser l;
  l.T_C_L = Pose(where, node, "T_C_L");
  l.T_C_M = Pose(where, node, "T_C_M");
  l.mirror_step_rad = Number(where, node, "mirror_step_rad");
  l.rotation_distance_m = Number(where, node, "rotation_distance_m");
  l.aperture_rad = Number(where, node, "aperture_rad");
  l.step_min = Integer(where, node, "step_min");
  l.step_max = Integer(where, node, "step_max");
  return l;
}

YAML::Node WriteGalvoLaser(const GalvoLaser& l) {
  YAML::Node node;
  node["T_C_L"] = WritePose(l.T_C_L);
  node["T_C_M"] = WritePose(l.T_C_M);
  node["mirror_step_rad"] = l.mirror_step_rad;
  node["rotation_distance_m"] = l.rotation_distance_m;
  node["aperture_rad"] = l.aperture_rad;
  node["step_min"] = l.step_min;
  node["step_max"] = l.step_max;
  return node;
}

void ReadMemsSection(const Context& where, const YAML::Node& node, MemsLaser* laser,
                     MirrorDynamicsOptions* dynamics) {
  RequireKnownKeys(where, node,
                   {"emitter", "T_C_M", "max_volts", "max_tilt_rad", "saturation", "T_C_Lens",
                    "lens_gain", "dynamics"});
  const Context emitter_where = Enter(where, "emitter");
  const YAML::Node emitter = Child(where, node, "emitter");
  RequireKnownKeys(emitter_where, emitter, {"origin_m", "direction"});
  laser->emitter_origin_C = Vector3(emitter_where, emitter, "origin_m");
  laser->emitter_direction_C = UnitVector3(emitter_where, emitter, "direction");
  laser->T_C_M = Pose(where, node, "T_C_M");
  laser->max_volts = Number(where, node, "max_volts");
  laser->max_tilt_rad = Vector2(where, node, "max_tilt_rad");
  laser->saturation = Vector2(where, node, "saturation");
  laser->T_C_Lens = Pose(where, node, "T_C_Lens");
  laser->lens_gain = Number(where, node, "lens_gain");
  *dynamics = ReadDynamics(Enter(where, "dynamics"), Child(where, node, "dynamics"));
}

YAML::Node WriteMemsSection(const MemsLaser& laser, const MirrorDynamicsOptions& dynamics) {
  YAML::Node node;
  node["emitter"]["origin_m"] = Numbers(laser.emitter_origin_C);
  node["emitter"]["direction"] = Numbers(laser.emitter_direction_C);
  node["T_C_M"] = WritePose(laser.T_C_M);
  node["max_volts"] = laser.max_volts;
  node["max_tilt_rad"] = Numbers(laser.max_tilt_rad);
  node["saturation"] = Numbers(laser.saturation);
  node["T_C_Lens"] = WritePose(laser.T_C_Lens);
  node["lens_gain"] = laser.lens_gain;
  node["dynamics"] = WriteDynamics(dynamics);
  return node;
}

ProjectionFunctions ReadProjectionFunctions(const Context& where, const YAML::Node& node) {
  RequireKnownKeys(where, node,
                   {"T_C_P", "volts_min", "volts_max", "f1", "f2", "f3", "f4", "f5", "f6"});
  ProjectionFunctions f;
  f.T_C_P = Pose(where, node, "T_C_P");
  f.volts_min = Vector2(where, node, "volts_min");
  f.volts_max = Vector2(where, node, "volts_max");
  Polynomial2d* const targets[6] = {&f.f1, &f.f2, &f.f3, &f.f4, &f.f5, &f.f6};
  for (int i = 0; i < 6; ++i) {
    *targets[i] =
        ReadPolynomial(Enter(where, kFunctionNames[i]), Child(where, node, kFunctionNames[i]));
  }
  return f;
}

YAML::Node WriteProjectionFunctions(const ProjectionFunctions& functions) {
  YAML::Node node;
  node["T_C_P"] = WritePose(functions.T_C_P);
  node["volts_min"] = Numbers(functions.volts_min);
  node["volts_max"] = Numbers(functions.volts_max);
  const Polynomial2d* const polynomials[6] = {&functions.f1, &functions.f2, &functions.f3,
                                              &functions.f4, &functions.f5, &functions.f6};
  for (int i = 0; i < 6; ++i) node[kFunctionNames[i]] = WritePolynomial(*polynomials[i]);
  return node;
}

std::vector<StepRecord> ReadStepRecords(const Context& where, const YAML::Node& node) {
  if (!node.IsMap()) Fail(where, node, "expected a mapping of calibration steps");
  std::vector<StepRecord> records;
  for (const auto& entry : node) {
    StepRecord r;
    if (!entry.first.IsScalar()) Fail(where, entry.first, "expected a step name as key");
    r.step = entry.first.Scalar();
    const Context at = Enter(where, r.step);
    const YAML::Node n = entry.second;
    RequireKnownKeys(at, n,
                     {"dataset", "date_utc", "residual_unit", "residual_rms", "residual_max",
                      "observations", "seconds", "params"});
    r.dataset = Text(at, n, "dataset");
    r.date_utc = Text(at, n, "date_utc");
    r.residual_unit = Text(at, n, "residual_unit");
    r.residual_rms = Number(at, n, "residual_rms");
    r.residual_max = Number(at, n, "residual_max");
    r.observations = Integer(at, n, "observations");
    r.seconds = Number(at, n, "seconds");
    const Context params_at = Enter(at, "params");
    const YAML::Node params = Child(at, n, "params");
    if (!params.IsMap()) Fail(params_at, params, "expected a mapping of parameters");
    for (const auto& p : params) {
      if (!p.first.IsScalar()) Fail(params_at, p.first, "expected a parameter name as key");
      const std::string name = p.first.Scalar();
      const Context p_at = Enter(params_at, name);
      RequireKnownKeys(p_at, p.second, {"value", "std"});
      r.params.push_back({name, Number(p_at, p.second, "value"), Number(p_at, p.second, "std")});
    }
    records.push_back(std::move(r));
  }
  return records;
}

YAML::Node WriteStepRecords(const std::vector<StepRecord>& records) {
  YAML::Node node(YAML::NodeType::Map);
  for (const StepRecord& r : records) {
    YAML::Node n;
    n["dataset"] = r.dataset;
    n["date_utc"] = r.date_utc;
    n["residual_unit"] = r.residual_unit;
    n["residual_rms"] = r.residual_rms;
    n["residual_max"] = r.residual_max;
    n["observations"] = r.observations;
    n["seconds"] = r.seconds;
    YAML::Node params(YAML::NodeType::Map);
    for (const ParameterEstimate& p : r.params) {
      YAML::Node entry;
      entry["value"] = p.value;
      entry["std"] = p.std;
      entry.SetStyle(YAML::EmitterStyle::Flow);
      params[p.name] = entry;
    }
    n["params"] = params;
    node[r.step] = n;
  }
  return node;
}

}  // namespace uwscan::scanner::yaml
