#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "viewer/scene/colour_map.hpp"
#include "viewer/scene/render_options.hpp"
#include "viewer/scene/scene.hpp"

// The colour of each point the viewer draws, computed outside VTK so that tests can predict
// every pixel of a picture.
namespace uwscan::viewer {

// Every stride-th point of each cloud is drawn: 1 when `total` fits in `max_points`, else the
// smallest stride that brings it under.
std::size_t PointStride(std::size_t total, std::size_t max_points);

// True for the modes drawn through the continuous colour map (with a colour bar).
inline bool IsContinuous(ColourMode mode) { return mode != ColourMode::kObject; }

// The value `mode` shows for points 0, stride, 2 stride, ... of `layer`: height along `up`
// (unit), error or intensity; empty for ColourMode::kObject. Throws uwscan::Error naming the
// layer when it has no values for the mode (no truth, no intensity).
std::vector<float> PointScalars(const CloudLayer& layer, ColourMode mode, const Eigen::Vector3d& up,
                                std::size_t stride);

// The colour of a point: the continuous map at its scalar for continuous modes; for kObject the
// categorical colour of its object id when the layer has ids (kNoValue for id -1), else of the
// layer's index.
Rgb PointColour(ColourMode mode, float scalar, const ScalarRange& range, int layer_index,
                std::optional<std::int32_t> object_id);

// The range a scene's colours span: `options.range` when set, else RobustRange over every
// drawn point's scalar (made symmetric about zero for deviations).
ScalarRange SceneRange(const std::vector<std::vector<float>>& scalars,
                       const RenderOptions& options);

}  // namespace uwscan::viewer
