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

// Whether the box hides the point (with the gap around it).
bool Covers(const Box& box, const Eigen::Vector2d& p) {
  return p.x() > box.low.x() - kGapPx && p.x() < box.high.x() + kGapPx &&
         p.y() > box.low.y() - kGapPx && p.y() < box.high.y() + kGapPx;
}

bool Inside(const Box& box, const Eigen::Vector2d& picture) {
  return box.low.x() >= 0.0 && box.low.y() >= 0.0 && box.high.x() <= picture.x() &&
         box.high.y() <= picture.y();
}

// The spots tried for a label, nearest first: on ring r (r = 1..max_rings) sixteen directions at
// r steps of a box height (and the gap) from its anchor, straight up first, then alternately
// either side of it.
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
    const std::vector<Eigen::Vector2d> spots = Spots(label, std::max(1, max_rings));
    const auto fits = [&](const Eigen::Vector2d& spot, bool clear_of_anchors) {
      const Box box = BoxAt(spot, label.size_px);
      const auto covers = [&](const LabelBox& other) { return Covers(box, other.anchor_px); };
      return Inside(box, picture_px) &&
             std::none_of(placed.begin(), placed.end(),
                          [&](const Box& other) { return Overlap(box, other); }) &&
             (!clear_of_anchors || std::none_of(labels.begin(), labels.end(), covers));
    };
    // Clear of every label's anchor if it can be, else at least of the other labels.
    auto chosen =
        std::find_if(spots.begin(), spots.end(), [&](const auto& p) { return fits(p, true); });
    if (chosen == spots.end())
      chosen =
          std::find_if(spots.begin(), spots.end(), [&](const auto& p) { return fits(p, false); });
    centres.push_back(chosen != spots.end() ? *chosen : spots.front());
    placed.push_back(BoxAt(centres.back(), label.size_px));
  }
  return centres;
}

}  // namespace uwscan::viewer
