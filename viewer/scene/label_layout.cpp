#include "viewer/scene/label_layout.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace uwscan::viewer {
namespace {

// Pixels kept clear between two boxes.
constexpr double kGapPx = 2.0;

struct Box {
  Eigen::Vector2d low, high;
};

Box BoxAt(const Eigen::Vector2d& centre, const Eigen::Vector2d& size) {
  const Eigen::Vector2d half = 0.5 * size;
  return {centre - half, centre + half};
}

bool Overlap(const Box& a, const Box& b) {
  return a.low.x() < b.high.x() + kGapPx && b.low.x() < a.high.x() + kGapPx &&
         a.low.y() < b.high.y() + kGapPx && b.low.y() < a.high.y() + kGapPx;
}

bool Inside(const Box& box, const Eigen::Vector2d& picture) {
  return box.low.x() >= 0.0 && box.low.y() >= 0.0 && box.high.x() <= picture.x() &&
         box.high.y() <= picture.y();
}

// The spots tried for a label, nearest first: on ring r (r = 1..max_rings) sixteen directions at
// r box heights from its anchor, straight up first, then alternately either side of it. Never
// the anchor itself: the label would hide what it names.
std::vector<Eigen::Vector2d> Spots(const LabelBox& label, int max_rings) {
  std::vector<Eigen::Vector2d> spots;
  const double step = std::max(label.size_px.y(), 1.0) + kGapPx;
  for (int r = 1; r <= max_rings; ++r) {
    for (int k = 0; k < 16; ++k) {
      const int turn = (k % 2 == 0 ? 1 : -1) * ((k + 1) / 2);
      const double angle = 0.5 * std::numbers::pi + turn * (2.0 * std::numbers::pi / 16.0);
      spots.push_back(label.anchor_px +
                      r * step * Eigen::Vector2d(std::cos(angle), std::sin(angle)));
    }
  }
  return spots;
}

}  // namespace

std::vector<Eigen::Vector2d> LayOutLabels(const std::vector<LabelBox>& labels,
                                          const Eigen::Vector2d& picture_px, int max_rings) {
  std::vector<Eigen::Vector2d> centres;
  std::vector<Box> placed;
  for (const LabelBox& label : labels) {
    const std::vector<Eigen::Vector2d> spots = Spots(label, max_rings);
    Eigen::Vector2d chosen = spots.front();
    for (const Eigen::Vector2d& spot : spots) {
      const Box box = BoxAt(spot, label.size_px);
      const bool free = std::none_of(placed.begin(), placed.end(),
                                     [&](const Box& other) { return Overlap(box, other); });
      if (free && Inside(box, picture_px)) {
        chosen = spot;
        break;
      }
    }
    centres.push_back(chosen);
    placed.push_back(BoxAt(chosen, label.size_px));
  }
  return centres;
}

}  // namespace uwscan::viewer
