#pragma once

// Reading typed fields from yaml-cpp nodes with errors that name the source, line and field.
// Included only by the .cpp files that parse YAML.

#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <initializer_list>
#include <string>

namespace uwscan::scanner::yaml {

// Where a node came from, for error messages: "file.yaml:12: field 'camera.fx_px': ...".
struct Context {
  std::string source;
  std::string path;  // dotted field path of the node
};

[[noreturn]] void Fail(const Context& where, const YAML::Node& node, const std::string& what);

YAML::Node Child(const Context& where, const YAML::Node& node, const std::string& key);
Context Enter(const Context& where, const std::string& key);

double Number(const Context& where, const YAML::Node& node, const std::string& key);
double NumberOr(const Context& where, const YAML::Node& node, const std::string& key,
                double fallback);
int Integer(const Context& where, const YAML::Node& node, const std::string& key);
// A scalar read as text (numbers included, as written).
std::string Text(const Context& where, const YAML::Node& node, const std::string& key);
Eigen::Vector3d Vector3(const Context& where, const YAML::Node& node, const std::string& key);
Eigen::VectorXd Vector(const Context& where, const YAML::Node& node, const std::string& key,
                       int size);
// {translation_m: [x, y, z], rotation_xyzw: [qx, qy, qz, qw]} -> rigid transform. The
// quaternion must be unit length to 1e-6 (it is then normalised exactly).
Eigen::Isometry3d Pose(const Context& where, const YAML::Node& node, const std::string& key);

// Throws naming the first key of a mapping that is not among `known`: a misspelt field must not
// fall back silently to its default.
void RequireKnownKeys(const Context& where, const YAML::Node& node,
                      std::initializer_list<const char*> known);

// Checks `uwscan_format: 1` at the root.
void CheckFormat(const Context& where, const YAML::Node& root);

}  // namespace uwscan::scanner::yaml
