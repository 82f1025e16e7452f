#pragma once

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <vector>

#include "scanner/common/yaml_fields.hpp"
#include "scanner/sim/scene.hpp"

namespace uwscan::scanner::sim {

// Reads the `objects` list of a scene (format in data/README.md): each object's pose,
// reflectance and geometry in {O}, procedural shapes generated, meshes loaded (paths relative
// to base_dir). Names are unique ("<shape>_<index>" when not given). Throws uwscan::Error
// naming source:line and the field. Included only by the scene reader.
std::vector<SceneObject> ReadSceneObjects(const yaml::Context& where, const YAML::Node& node,
                                          const std::filesystem::path& base_dir);

}  // namespace uwscan::scanner::sim
