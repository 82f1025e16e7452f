#pragma once

#include <Eigen/Core>
#include <vector>

namespace uwscan::viewer {

// A label to place on a picture: the pixel it names and the size of its text box, pixels (x
// right, y up, as VTK's display coordinates).
struct LabelBox {
  Eigen::Vector2d anchor_px = Eigen::Vector2d::Zero();
  Eigen::Vector2d size_px = Eigen::Vector2d::Zero();
};

// The centre of each label's box, in the labels' order: each goes to the first spot near its
// anchor (rings of sixteen spots, a box height apart, up to max_rings out; straight above the
// anchor first; never on it, so that the label does not hide what it names) where its box
// overlaps none placed before it and lies inside the picture; a label with no such spot goes
// straight above its anchor. Earlier labels (the more important) get the nearer spots. max_rings
// >= 1. The same input gives the same places.
std::vector<Eigen::Vector2d> LayOutLabels(const std::vector<LabelBox>& labels,
                                          const Eigen::Vector2d& picture_px, int max_rings = 6);

}  // namespace uwscan::viewer
