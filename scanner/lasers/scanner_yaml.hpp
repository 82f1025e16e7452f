#pragma once

// Readers for the YAML sections that several scanner files share (camera, viewport), so the
// galvanometer and the MEMS scanner files spell them identically. Included only by the .cpp
// files that parse YAML.

#include <string>

#include "scanner/common/error.hpp"
#include "scanner/optics/flat_viewport.hpp"
#include "scanner/optics/pinhole_camera.hpp"
#include "scanner/common/yaml_fields.hpp"

namespace uwscan::scanner::yaml {

// `camera:` {width_px, height_px, fx_px, fy_px, cx_px, cy_px, distortion: [k1 k2 p1 p2 k3]}.
PinholeCamera ReadCamera(const Context& where, const YAML::Node& node);

// A viewport {normal (unit), distance_m, thickness_m, n_air?, n_glass?, n_water?}.
FlatViewport ReadViewport(const Context& where, const YAML::Node& node);

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
