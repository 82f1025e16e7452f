#include "ros/conversions/dive_description.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>

#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::ros {
namespace {

constexpr int kFormat = 1;

// The navigation noise's fields by name, in file order.
struct NoiseField {
  const char* name;
  double mapping::NavigationNoise::*value;
};
constexpr NoiseField kNoiseFields[] = {
    {"position_walk_m_per_sqrt_s", &mapping::NavigationNoise::position_walk_m_per_sqrt_s},
    {"heading_walk_rad_per_sqrt_s", &mapping::NavigationNoise::heading_walk_rad_per_sqrt_s},
    {"speed_scale_sigma", &mapping::NavigationNoise::speed_scale_sigma},
    {"heading_bias_sigma_rad", &mapping::NavigationNoise::heading_bias_sigma_rad},
    {"depth_sigma_m", &mapping::NavigationNoise::depth_sigma_m},
    {"roll_pitch_sigma_rad", &mapping::NavigationNoise::roll_pitch_sigma_rad},
};

YAML::Node Field(const YAML::Node& root, const std::string& name, const std::string& source) {
  const YAML::Node node = root[name];
  if (!node) throw Error(source + ": dive description lacks '" + name + "'");
  return node;
}

template <typename T>
T As(const YAML::Node& node, const std::string& name, const std::string& source) {
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw Error(source + ": dive description field '" + name + "' has the wrong type");
  }
}

}  // namespace

std::string DiveDescriptionToYaml(const DiveDescription& d) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "uwscan_format" << YAML::Value << kFormat;
  out << YAML::Key << "producer" << YAML::Value << d.header.producer;
  out << YAML::Key << "time_origin_s" << YAML::Value << YAML::Precision(17) << d.time_origin_s;
  out << YAML::Key << "scanner" << YAML::Value << YAML::Literal
      << scanner::ScannerToYaml(d.header.scanner);
  out << YAML::Key << "scan_pattern" << YAML::Value << YAML::Literal
      << scanner::ScanPatternToYaml(d.header.scan_pattern);
  if (d.header.navigation_noise) {
    out << YAML::Key << "navigation_noise" << YAML::Value << YAML::BeginMap;
    for (const NoiseField& f : kNoiseFields) {
      out << YAML::Key << f.name << YAML::Value << YAML::Precision(17)
          << (*d.header.navigation_noise).*f.value;
    }
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  return out.c_str();
}

DiveDescription ParseDiveDescription(const std::string& text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw Error(source + ": dive description is not YAML (" + e.what() + ")");
  }
  if (!root.IsMap()) throw Error(source + ": dive description is not a YAML map");
  const int format = As<int>(Field(root, "uwscan_format", source), "uwscan_format", source);
  if (format != kFormat) {
    throw Error(source + ": dive description format " + std::to_string(format) +
                ", this uwscan reads " + std::to_string(kFormat));
  }
  DiveDescription d;
  if (root["producer"]) d.header.producer = As<std::string>(root["producer"], "producer", source);
  d.time_origin_s = As<double>(Field(root, "time_origin_s", source), "time_origin_s", source);
  if (!std::isfinite(d.time_origin_s) || d.time_origin_s < 0.0) {
    throw Error(source + ": dive description field 'time_origin_s' must be finite and >= 0");
  }
  d.header.scanner = scanner::ParseScanner(
      As<std::string>(Field(root, "scanner", source), "scanner", source), source + " (scanner)");
  d.header.scan_pattern = scanner::ParseScanPattern(
      As<std::string>(Field(root, "scan_pattern", source), "scan_pattern", source),
      source + " (scan_pattern)");
  if (d.header.scan_pattern.kind != d.header.scanner.kind()) {
    throw Error(source + ": dive description's scan pattern is for another kind of scanner");
  }
  if (const YAML::Node noise = root["navigation_noise"]) {
    mapping::NavigationNoise n;
    for (const NoiseField& f : kNoiseFields) {
      n.*f.value = As<double>(Field(noise, f.name, source),
                              std::string("navigation_noise.") + f.name, source);
    }
    try {
      n.Check();
    } catch (const Error& e) {
      throw Error(source + ": " + e.what());
    }
    d.header.navigation_noise = n;
  }
  return d;
}

}  // namespace uwscan::ros
