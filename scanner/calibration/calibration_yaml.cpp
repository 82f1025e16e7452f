#include "scanner/calibration/calibration_yaml.hpp"

#include <charconv>
#include <cmath>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::calibration::calibration_yaml {

using namespace sim::scene_yaml;

PatternSpec ReadPattern(const Context& where, const YAML::Node& node) {
  if (!node.IsMap()) yaml::Fail(where, node, "expected a mapping {type, columns, rows, ...}");
  PatternSpec spec;
  const std::string type = String(where, node, "type");
  if (type == "chessboard") {
    spec.type = PatternType::kChessboard;
    yaml::RequireKnownKeys(where, node, {"type", "columns", "rows", "square_m"});
  } else if (type == "charuco") {
    spec.type = PatternType::kCharuco;
    yaml::RequireKnownKeys(where, node,
                           {"type", "columns", "rows", "square_m", "marker_m", "dictionary"});
  } else {
    FailField(where, node, "type", "got '" + type + "', expected chessboard or charuco");
  }
  spec.columns = Integer(where, node, "columns", 2);
  spec.rows = Integer(where, node, "rows", 2);
  spec.square_m = Number(where, node, "square_m", Range::kPositive);
  if (spec.type == PatternType::kCharuco) {
    spec.marker_m = Number(where, node, "marker_m", Range::kPositive);
    if (Has(node, "dictionary")) spec.dictionary = String(where, node, "dictionary");
  }
  Checked(where, node, [&] { spec.Check(); });
  return spec;
}

void EmitPattern(YAML::Emitter& out, const PatternSpec& spec) {
  out << YAML::Flow << YAML::BeginMap;
  out << YAML::Key << "type" << YAML::Value
      << (spec.type == PatternType::kChessboard ? "chessboard" : "charuco");
  out << YAML::Key << "columns" << YAML::Value << spec.columns;
  out << YAML::Key << "rows" << YAML::Value << spec.rows;
  out << YAML::Key << "square_m" << YAML::Value << Shortest(spec.square_m);
  if (spec.type == PatternType::kCharuco) {
    out << YAML::Key << "marker_m" << YAML::Value << Shortest(spec.marker_m);
    out << YAML::Key << "dictionary" << YAML::Value << spec.dictionary;
  }
  out << YAML::EndMap;
}

void EmitPose(YAML::Emitter& out, const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  out << YAML::Flow << YAML::BeginMap;
  out << YAML::Key << "translation_m" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (int k = 0; k < 3; ++k) out << Shortest(T.translation()[k]);
  out << YAML::EndSeq;
  out << YAML::Key << "rotation_xyzw" << YAML::Value << YAML::Flow << YAML::BeginSeq
      << Shortest(q.x()) << Shortest(q.y()) << Shortest(q.z()) << Shortest(q.w()) << YAML::EndSeq;
  out << YAML::EndMap;
}

std::string Shortest(double v) {
  if (!std::isfinite(v)) throw Error("cannot write a non-finite number to YAML");
  char buffer[32];
  const std::to_chars_result r = std::to_chars(buffer, buffer + sizeof(buffer), v);
  return std::string(buffer, r.ptr);
}

YAML::Node LoadYaml(const std::string& text, const std::string& source) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw Error(source + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
}

}  // namespace uwscan::scanner::calibration::calibration_yaml
