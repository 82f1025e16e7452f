#include "scanner/lasers/scan_pattern.hpp"

#include <sstream>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/common/yaml_fields.hpp"

namespace uwscan::scanner {

const char* ToString(ScannerKind kind) { return kind == ScannerKind::kGalvo ? "galvo" : "mems"; }

void GalvoScan::Check() const {
  const OptionChecks check("GalvoScan");
  check.AtLeast("step_stride", step_stride, 1);
  check.Require(step_max >= step_min, "step_max", ">= step_min (" + std::to_string(step_min) + ")",
                step_max);
  check.InRange("frame_rate_hz", frame_rate_hz, 0.0, 1e6, Interval::kOpen, "Hz");
}

void MemsScan::Check() const {
  const OptionChecks check("MemsScan");
  check.AtLeast("lines", lines, 1);
  check.AtLeast("waypoints_per_line", waypoints_per_line, 2);
  check.InRange("waypoint_rate_hz", waypoint_rate_hz, 0.0, 1e7, Interval::kOpen, "Hz");
  check.InRange("fov_fraction_x", fov_fraction_x, 0.0, 1.0, Interval::kOpenLow);
  check.InRange("fov_fraction_y", fov_fraction_y, 0.0, 1.0, Interval::kOpenLow);
}

void ScanPattern::Check() const {
  if (kind == ScannerKind::kGalvo) {
    galvo.Check();
  } else {
    mems.Check();
  }
}

std::string ScanPatternToYaml(const ScanPattern& pattern) {
  std::ostringstream out;
  out.precision(17);
  out << "uwscan_format: 1\n";
  out << "kind: " << ToString(pattern.kind) << "\n";
  if (pattern.kind == ScannerKind::kGalvo) {
    const GalvoScan& g = pattern.galvo;
    out << "galvo: {step_min: " << g.step_min << ", step_max: " << g.step_max
        << ", step_stride: " << g.step_stride << ", frame_rate_hz: " << g.frame_rate_hz << "}\n";
  } else {
    const MemsScan& m = pattern.mems;
    out << "mems: {lines: " << m.lines << ", waypoints_per_line: " << m.waypoints_per_line
        << ", waypoint_rate_hz: " << m.waypoint_rate_hz << ", fov_fraction: [" << m.fov_fraction_x
        << ", " << m.fov_fraction_y << "]}\n";
  }
  return out.str();
}

ScanPattern ParseScanPattern(const std::string& yaml_text, const std::string& source_name) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw Error(source_name + ": not valid YAML: " + e.what());
  }
  const yaml::Context where{source_name, ""};
  yaml::CheckFormat(where, root);
  yaml::RequireKnownKeys(where, root, {"uwscan_format", "kind", "galvo", "mems"});
  ScanPattern pattern;
  const YAML::Node kind = yaml::Child(where, root, "kind");
  const std::string kind_name = kind.IsScalar() ? kind.as<std::string>() : "";
  if (kind_name == "galvo") {
    pattern.kind = ScannerKind::kGalvo;
    const yaml::Context at = yaml::Enter(where, "galvo");
    const YAML::Node g = yaml::Child(where, root, "galvo");
    yaml::RequireKnownKeys(at, g, {"step_min", "step_max", "step_stride", "frame_rate_hz"});
    pattern.galvo.step_min = yaml::Integer(at, g, "step_min");
    pattern.galvo.step_max = yaml::Integer(at, g, "step_max");
    pattern.galvo.step_stride = yaml::Integer(at, g, "step_stride");
    pattern.galvo.frame_rate_hz = yaml::Number(at, g, "frame_rate_hz");
  } else if (kind_name == "mems") {
    pattern.kind = ScannerKind::kMems;
    const yaml::Context at = yaml::Enter(where, "mems");
    const YAML::Node m = yaml::Child(where, root, "mems");
    yaml::RequireKnownKeys(at, m,
                           {"lines", "waypoints_per_line", "waypoint_rate_hz", "fov_fraction"});
    pattern.mems.lines = yaml::Integer(at, m, "lines");
    pattern.mems.waypoints_per_line = yaml::Integer(at, m, "waypoints_per_line");
    pattern.mems.waypoint_rate_hz = yaml::Number(at, m, "waypoint_rate_hz");
    const Eigen::VectorXd fov = yaml::Vector(at, m, "fov_fraction", 2);
    pattern.mems.fov_fraction_x = fov[0];
    pattern.mems.fov_fraction_y = fov[1];
  } else {
    yaml::Fail(yaml::Enter(where, "kind"), kind, "expected 'galvo' or 'mems'");
  }
  try {
    pattern.Check();
  } catch (const Error& e) {
    throw Error(source_name + ": " + e.what());
  }
  return pattern;
}

}  // namespace uwscan::scanner
