#include "viewer/scene/label_layout.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace uwscan::viewer {
namespace {

bool Overlap(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& size_a,
             const Eigen::Vector2d& size_b) {
  const Eigen::Vector2d reach = 0.5 * (size_a + size_b);
  return std::abs(a.x() - b.x()) < reach.x() && std::abs(a.y() - b.y()) < reach.y();
}

// Twelve labels named in a tight column and a cluster, as the regions of a survey's findings are:
// every one placed clear of the others, inside the picture and near what it names.
TEST(LabelLayout, CrowdedLabelsEachFindAFreeSpotNearTheirAnchor) {
  std::vector<LabelBox> labels;
  for (int i = 0; i < 8; ++i)
    labels.push_back({Eigen::Vector2d(400.0, 300.0 + 20.0 * i), Eigen::Vector2d(180.0, 22.0)});
  for (int i = 0; i < 4; ++i)
    labels.push_back({Eigen::Vector2d(250.0 + 3.0 * i, 250.0), Eigen::Vector2d(150.0, 22.0)});
  const Eigen::Vector2d picture(800.0, 900.0);
  const std::vector<Eigen::Vector2d> centres = LayOutLabels(labels, picture);
  ASSERT_EQ(centres.size(), labels.size());
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const Eigen::Vector2d half = 0.5 * labels[i].size_px;
    EXPECT_GE(centres[i].x() - half.x(), 0.0) << "label " << i;
    EXPECT_GE(centres[i].y() - half.y(), 0.0) << "label " << i;
    EXPECT_LE(centres[i].x() + half.x(), picture.x()) << "label " << i;
    EXPECT_LE(centres[i].y() + half.y(), picture.y()) << "label " << i;
    EXPECT_LT((centres[i] - labels[i].anchor_px).norm(), 6 * 24.0 + 1.0) << "label " << i;
    for (std::size_t j = 0; j < i; ++j) {
      EXPECT_FALSE(Overlap(centres[i], centres[j], labels[i].size_px, labels[j].size_px))
          << "labels " << j << " and " << i;
    }
  }
  EXPECT_EQ(LayOutLabels(labels, picture), centres);
}

bool Hides(const Eigen::Vector2d& centre, const Eigen::Vector2d& size, const Eigen::Vector2d& p) {
  return std::abs(p.x() - centre.x()) < 0.5 * size.x() &&
         std::abs(p.y() - centre.y()) < 0.5 * size.y();
}

// Wide labels whose anchors lie side by side on one row, as regions along a pipe do: no label may
// sit on any named point, its own or another's, nor on another label.
TEST(LabelLayout, WideLabelsInARowHideNoAnchor) {
  std::vector<LabelBox> labels;
  for (int i = 0; i < 6; ++i)
    labels.push_back({Eigen::Vector2d(250.0 + 40.0 * i, 400.0), Eigen::Vector2d(180.0, 22.0)});
  const std::vector<Eigen::Vector2d> centres = LayOutLabels(labels, Eigen::Vector2d(800, 800));
  for (std::size_t i = 0; i < labels.size(); ++i) {
    for (std::size_t j = 0; j < labels.size(); ++j) {
      EXPECT_FALSE(Hides(centres[i], labels[i].size_px, labels[j].anchor_px))
          << "label " << i << " hides anchor " << j;
      if (j < i) {
        EXPECT_FALSE(Overlap(centres[i], centres[j], labels[i].size_px, labels[j].size_px))
            << "labels " << j << " and " << i;
      }
    }
  }
}

// No spot fits a picture smaller than the label, nor rings asked as 0: the label goes straight
// above its anchor, the same every time.
TEST(LabelLayout, WithNoFreeSpotALabelGoesStraightAboveItsAnchor) {
  const LabelBox label{Eigen::Vector2d(20.0, 20.0), Eigen::Vector2d(100.0, 20.0)};
  for (const int rings : {0, 1, 6}) {
    const std::vector<Eigen::Vector2d> centres =
        LayOutLabels({label}, Eigen::Vector2d(40.0, 40.0), rings);
    ASSERT_EQ(centres.size(), 1u);
    EXPECT_NEAR(centres[0].x(), 20.0, 1e-9) << rings << " rings";
    EXPECT_NEAR(centres[0].y(), 20.0 + 22.0, 1e-9) << rings << " rings";
  }
}

// A label alone goes straight above what it names, its box clear of the anchor.
TEST(LabelLayout, ALoneLabelSitsJustAboveItsAnchor) {
  const LabelBox label{Eigen::Vector2d(100.0, 100.0), Eigen::Vector2d(80.0, 20.0)};
  const std::vector<Eigen::Vector2d> centres = LayOutLabels({label}, Eigen::Vector2d(200, 200));
  ASSERT_EQ(centres.size(), 1u);
  EXPECT_NEAR(centres[0].x(), 100.0, 1e-9);
  EXPECT_GT(centres[0].y() - 10.0, 100.0);
  EXPECT_LT(centres[0].y(), 100.0 + 2 * 20.0 + 4.0);
}

}  // namespace
}  // namespace uwscan::viewer
