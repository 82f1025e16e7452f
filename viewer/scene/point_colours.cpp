#include "viewer/scene/point_colours.hpp"

#include "scanner/common/error.hpp"

namespace uwscan::viewer {

std::size_t PointStride(std::size_t total, std::size_t max_points) {
  if (max_points == 0 || total <= max_points) return 1;
  return (total + max_points - 1) / max_points;
}

std::vector<float> PointScalars(const CloudLayer& layer, ColourMode mode, const Eigen::Vector3d& up,
                                std::size_t stride) {
  std::vector<float> scalars;
  if (mode == ColourMode::kObject) return scalars;
  const std::vector<float>* values = nullptr;
  if (mode == ColourMode::kError) {
    if (layer.error_m.size() != layer.size()) {
      throw Error(
          "colour by error: " + layer.name +
          " has no ground truth (simulated dive logs have it; give any other cloud of a simulated "
          "scene its scene with --scene)");
    }
    values = &layer.error_m;
  } else if (mode == ColourMode::kDeviation) {
    if (layer.deviation_m.size() != layer.size()) {
      throw Error("colour by deviation: " + layer.name +
                  " has no deviations (`uwscan compare --json` reports have them)");
    }
    values = &layer.deviation_m;
  } else if (mode == ColourMode::kIntensity) {
    if (layer.intensity.size() != layer.size()) {
      throw Error("colour by intensity: " + layer.name + " has no intensity values");
    }
    values = &layer.intensity;
  }
  scalars.reserve(layer.size() / stride + 1);
  // Height is taken in double from the absolute position: float offsets would lose the origin.
  const double origin_height = up.dot(layer.origin);
  for (std::size_t i = 0; i < layer.size(); i += stride) {
    scalars.push_back(
        values ? (*values)[i]
               : static_cast<float>(origin_height + up.dot(layer.points[i].cast<double>())));
  }
  return scalars;
}

Rgb PointColour(ColourMode mode, float scalar, const ScalarRange& range, int layer_index,
                std::optional<std::int32_t> object_id) {
  if (mode == ColourMode::kDeviation) return DivergingColour(range.Normalise(scalar));
  if (IsContinuous(mode)) return ContinuousColour(range.Normalise(scalar));
  if (!object_id) return CategoricalColour(layer_index);
  return *object_id < 0 ? kNoValue : CategoricalColour(*object_id);
}

ScalarRange SceneRange(const std::vector<std::vector<float>>& scalars,
                       const RenderOptions& options) {
  if (options.range) return *options.range;
  std::vector<float> all;
  for (const std::vector<float>& s : scalars) all.insert(all.end(), s.begin(), s.end());
  const ScalarRange robust = RobustRange(all);
  if (options.colour != ColourMode::kDeviation) return robust;
  // Symmetric about zero, so that the map's middle is no change.
  const double reach = std::max(std::abs(robust.lo), std::abs(robust.hi));
  return {-reach, reach};
}

}  // namespace uwscan::viewer
