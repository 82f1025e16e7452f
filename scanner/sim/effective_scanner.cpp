#include "scanner/sim/effective_scanner.hpp"

#include <yaml-cpp/yaml.h>

#include "scanner/common/error.hpp"

namespace uwscan::scanner::sim {
namespace {

bool EndsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Every mapping under a key ending in "viewport" (camera_viewport, laser_viewport, ...) is a
// flat viewport, wherever it sits in the file.
void AdjustViewports(YAML::Node node, const Scene& scene) {
  if (!node.IsMap()) return;
  for (auto entry : node) {
    const std::string key = entry.first.as<std::string>();
    if (key == "calibration") continue;  // a calibration file's records are history, not optics
    YAML::Node value = entry.second;
    if (EndsWith(key, "viewport") && value.IsMap()) {
      if (scene.effects.refraction) {
        value["n_water"] = scene.water.refractive_index;
      } else {
        const double n_air = value["n_air"] ? value["n_air"].as<double>() : 1.0;
        value["n_glass"] = n_air;
        value["n_water"] = n_air;
      }
    } else {
      AdjustViewports(value, scene);
    }
  }
}

}  // namespace

std::string EffectiveScannerYaml(const Scene& scene) {
  YAML::Node root;
  try {
    root = YAML::Load(scene.scanner.yaml_text);
  } catch (const YAML::Exception& e) {
    throw Error(scene.scanner.file.string() + ": not valid YAML: " + e.what());
  }
  AdjustViewports(root, scene);
  if (!scene.effects.lens_distortion && root["camera"] && root["camera"]["distortion"]) {
    YAML::Node zero(YAML::NodeType::Sequence);
    for (int i = 0; i < 5; ++i) zero.push_back(0.0);
    root["camera"]["distortion"] = zero;
  }
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << root;
  return "# Scanner as simulated by uwscan from " + scene.scanner.file.filename().string() +
         " (scene " + scene.source + "): water index, refraction and distortion applied.\n" +
         out.c_str() + "\n";
}

}  // namespace uwscan::scanner::sim
