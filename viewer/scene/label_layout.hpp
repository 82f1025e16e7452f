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
// anchor (rings of sixteen spots, a box height and 2 px apart, up to max_rings out, at least 1;
// straight above the anchor first) where its box lies inside the picture, overlaps no box placed
// before it and hides no label's anchor (so that no label hides what it or another names); failing
// that, the first such spot that may hide an anchor; failing that, straight above its anchor.
// Earlier labels (the more important) get the nearer spots. The same input gives the same places.
std::vector<Eigen::Vector2d> LayOutLabels(const std::vector<LabelBox>& labels,
                                          const Eigen::Vector2d& picture_px, int max_rings = 6);

}  // namespace uwscan::viewer
