#include "mapping/change/local_statistics.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

// Inspected core points 1 cm apart over a 60 cm square, with a 10 cm hole not inspected in its
// middle.
std::vector<CoreDeviation> SquareWithAHole() {
  std::vector<CoreDeviation> d;
  for (int i = 0; i < 60; ++i) {
    for (int j = 0; j < 60; ++j) {
      CoreDeviation c;
      c.point_W = Eigen::Vector3d(0.01 * i, 0.01 * j, 0.0);
      c.deviation_m = 0.0;
      c.lod_m = 0.001;
      const bool hole = std::abs(i - 30) <= 5 && std::abs(j - 30) <= 5;
      c.status = hole ? SurfaceStatus::kNotInspected : SurfaceStatus::kUnchanged;
      d.push_back(c);
    }
  }
  return d;
}

TEST(AtSurfaceEdge, TheBandAlongTheBorderAndAroundAHoleIsAnEdgeTheRestWhole) {
  const std::vector<CoreDeviation> d = SquareWithAHole();
  const std::vector<char> edge = AtSurfaceEdge(d, 0.05);
  ASSERT_EQ(edge.size(), d.size());
  for (std::size_t k = 0; k < d.size(); ++k) {
    const int i = static_cast<int>(k / 60), j = static_cast<int>(k % 60);
    // Core spacings to the last row or column, and to the hole (0 inside it).
    const int to_border = std::min({i, j, 59 - i, 59 - j});
    const double to_hole =
        std::hypot(std::max(0, std::abs(i - 30) - 5), std::max(0, std::abs(j - 30) - 5));
    SCOPED_TRACE("core point " + std::to_string(i) + ", " + std::to_string(j));
    if (to_hole == 0.0) {
      EXPECT_FALSE(edge[k]);  // not inspected: in no group at all
    } else if (to_border <= 1 || to_hole <= 1.0) {
      EXPECT_TRUE(edge[k]);
    } else if (to_border >= 5 && to_hole >= 5.0) {
      EXPECT_FALSE(edge[k]);
    }
  }
}

TEST(AtSurfaceEdge, NothingInspectedGivesNoEdgeAndABadRadiusIsRefused) {
  std::vector<CoreDeviation> d = SquareWithAHole();
  for (CoreDeviation& c : d) c.status = SurfaceStatus::kNotInspected;
  for (char e : AtSurfaceEdge(d, 0.05)) EXPECT_FALSE(e);
  EXPECT_THROW(AtSurfaceEdge(d, 0.0), Error);
}

}  // namespace
}  // namespace uwscan::mapping
