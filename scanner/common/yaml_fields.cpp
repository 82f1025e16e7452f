#include "scanner/common/yaml_fields.hpp"

#include <cmath>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::yaml {

void Fail(const Context& where, const YAML::Node& node, const std::string& what) {
  std::string location = where.source;
  if (node.IsDefined() && node.Mark().line >= 0) {
    location += ":" + std::to_string(node.Mark().line + 1);
  }
  throw Error(location + ": field '" + where.path + "': " + what);
}

Context Enter(const Context& where, const std::string& key) {
  return Context{where.source, where.path.empty() ? key : where.path + "." + key};
}

YAML::Node Child(const Context& where, const YAML::Node& node, const std::string& key) {
  if (!node.IsMap()) Fail(where, node, "expected a mapping");
  YAML::Node child = node[key];
  if (!child.IsDefined() || child.IsNull()) {
    Fail(Enter(where, key), node, "missing");
  }
  return child;
}

namespace {

double ToNumber(const Context& where, const YAML::Node& node) {
  if (!node.IsScalar()) Fail(where, node, "expected a number");
  double value = 0.0;
  if (!YAML::convert<double>::decode(node, value) || !std::isfinite(value)) {
    Fail(where, node, "expected a finite number, got '" + node.Scalar() + "'");
  }
  return value;
}

}  // namespace

double Number(const Context& where, const YAML::Node& node, const std::string& key) {
  return ToNumber(Enter(where, key), Child(where, node, key));
}

double NumberOr(const Context& where, const YAML::Node& node, const std::string& key,
                double fallback) {
  if (!node[key].IsDefined()) return fallback;
  return Number(where, node, key);
}

int Integer(const Context& where, const YAML::Node& node, const std::string& key) {
  const YAML::Node child = Child(where, node, key);
  int value = 0;
  if (!child.IsScalar() || !YAML::convert<int>::decode(child, value)) {
    Fail(Enter(where, key), child, "expected an integer");
  }
  return value;
}

std::string Text(const Context& where, const YAML::Node& node, const std::string& key) {
  const YAML::Node child = Child(where, node, key);
  if (!child.IsScalar()) Fail(Enter(where, key), child, "expected text");
  return child.Scalar();
}

Eigen::VectorXd Vector(const Context& where, const YAML::Node& node, const std::string& key,
                       int size) {
  const Context here = Enter(where, key);
  const YAML::Node child = Child(where, node, key);
  if (!child.IsSequence() || static_cast<int>(child.size()) != size) {
    Fail(here, child, "expected a list of " + std::to_string(size) + " numbers");
  }
  Eigen::VectorXd v(size);
  for (int i = 0; i < size; ++i) {
    v[i] = ToNumber(Context{here.source, here.path + "[" + std::to_string(i) + "]"}, child[i]);
  }
  return v;
}

Eigen::Vector3d Vector3(const Context& where, const YAML::Node& node, const std::string& key) {
  return Vector(where, node, key, 3);
}

Eigen::Isometry3d Pose(const Context& where, const YAML::Node& node, const std::string& key) {
  const Context here = Enter(where, key);
  const YAML::Node pose = Child(where, node, key);
  RequireKnownKeys(here, pose, {"translation_m", "rotation_xyzw"});
  const Eigen::Vector3d t = Vector3(here, pose, "translation_m");
  const Eigen::Vector4d q = Vector(here, pose, "rotation_xyzw", 4);
  if (std::abs(q.norm() - 1.0) > 1e-6) {
    Fail(Enter(here, "rotation_xyzw"), pose["rotation_xyzw"],
         "expected a unit quaternion [qx, qy, qz, qw]");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
  T.translation() = t;
  return T;
}

void RequireKnownKeys(const Context& where, const YAML::Node& node,
                      std::initializer_list<const char*> known) {
  if (!node.IsMap()) Fail(where, node, "expected a mapping");
  for (const auto& entry : node) {
    const std::string key = entry.first.Scalar();
    bool found = false;
    for (const char* k : known) found = found || key == k;
    if (!found) Fail(Enter(where, key), entry.first, "unknown field (misspelt?)");
  }
}

void CheckFormat(const Context& where, const YAML::Node& root) {
  if (!root.IsMap()) Fail(where, root, "expected a YAML mapping at the top level");
  const int format = Integer(where, root, "uwscan_format");
  if (format != 1) {
    Fail(Enter(where, "uwscan_format"), root["uwscan_format"],
         "unsupported version " + std::to_string(format) + " (this build reads 1)");
  }
}

}  // namespace uwscan::scanner::yaml
