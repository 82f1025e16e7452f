#pragma once

// YAML pieces shared by the calibration files (dataset manifest, truth file, calibration scene),
// on top of scanner/common/yaml_fields.hpp and scanner/sim/scene_fields.hpp: every failure names
// "file:line: field 'a.b': ...". Included only by the .cpp files that read or write them.

#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <string>

#include "scanner/calibration/observations.hpp"
#include "scanner/common/yaml_fields.hpp"
#include "scanner/sim/scene_fields.hpp"

namespace uwscan::scanner::calibration::calibration_yaml {

using yaml::Context;

// `pattern:` {type: chessboard, columns, rows, square_m} or {type: charuco, columns, rows,
// square_m, marker_m, dictionary (default DICT_4X4_50)}; checked (PatternSpec::Check).
PatternSpec ReadPattern(const Context& where, const YAML::Node& node);
void EmitPattern(YAML::Emitter& out, const PatternSpec& spec);

// {translation_m: [x, y, z], rotation_xyzw: [qx, qy, qz, qw]} written so that it reads back to
// the same doubles (yaml::Pose reads it).
void EmitPose(YAML::Emitter& out, const Eigen::Isometry3d& T);

// The shortest decimal text that reads back to exactly `v` ("0.03", not "0.029999999999999999").
std::string Shortest(double v);

// Parses YAML text, failing with "source:line: not valid YAML: ..." on a syntax error.
YAML::Node LoadYaml(const std::string& text, const std::string& source);

}  // namespace uwscan::scanner::calibration::calibration_yaml
