#pragma once

// Reading and writing the sections of a scanner file (data/README.md), shared by the
// galvanometer and the MEMS scanner so both spell them identically. Included only by the .cpp
// files that read or write scanner files; the entry points are in scanner_file.hpp.

#include <string>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/common/yaml_fields.hpp"
#include "scanner/lasers/calibration_record.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"
#include "scanner/lasers/mems_scanner_model.hpp"

namespace uwscan::scanner::yaml {

// `camera:` {width_px, height_px, fx_px, fy_px, cx_px, cy_px, distortion: [k1 k2 p1 p2 k3]}.
PinholeCamera ReadCamera(const Context& where, const YAML::Node& node);
YAML::Node WriteCamera(const PinholeCamera& camera);

// A viewport {normal (unit), distance_m, thickness_m, n_air?, n_glass?, n_water?}.
FlatViewport ReadViewport(const Context& where, const YAML::Node& node);
YAML::Node WriteViewport(const FlatViewport& viewport);

// `laser:` of a galvanometer scanner (its viewport is the separate `laser_viewport:`).
GalvoLaser ReadGalvoLaser(const Context& where, const YAML::Node& node);
YAML::Node WriteGalvoLaser(const GalvoLaser& laser);

// `mems:` of a MEMS scanner: the laser without its viewport, and the mirror dynamics.
void ReadMemsSection(const Context& where, const YAML::Node& node, MemsLaser* laser,
                     MirrorDynamicsOptions* dynamics);
YAML::Node WriteMemsSection(const MemsLaser& laser, const MirrorDynamicsOptions& dynamics);

// `projection_functions:` {T_C_P, volts_min, volts_max, f1..f6}.
ProjectionFunctions ReadProjectionFunctions(const Context& where, const YAML::Node& node);
YAML::Node WriteProjectionFunctions(const ProjectionFunctions& functions);

// `calibration:` {step: {dataset, date_utc, residual_unit, residual_rms, residual_max,
// observations, seconds, params: {name: {value, std}}}}, in file order.
std::vector<StepRecord> ReadStepRecords(const Context& where, const YAML::Node& node);
YAML::Node WriteStepRecords(const std::vector<StepRecord>& records);

// {translation_m, rotation_xyzw}, the form yaml::Pose reads.
YAML::Node WritePose(const Eigen::Isometry3d& T);

// Runs a Check() and prefixes its message with the source and section it came from.
template <typename T>
void CheckSection(const T& value, const std::string& source, const std::string& section) {
  try {
    value.Check();
  } catch (const Error& e) {
    throw Error(source + ": section '" + section + "': " + e.what());
  }
}

}  // namespace uwscan::scanner::yaml
