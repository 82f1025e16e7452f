#include "viewer/plots/legend_place.hpp"

#include <gtest/gtest.h>

namespace uwscan::viewer {
namespace {

PlotSeries Points(std::vector<double> x, std::vector<double> y) {
  return {"p", std::move(x), std::move(y), SeriesStyle::kPoints, {}};
}

TEST(PlaceLegend, TakesTheEmptiestThirdInItsOrderOfPreference) {
  PlotSpec spec;
  // Points in the top right and bottom left corners: the top left is the first empty place.
  spec.series = {Points({0.0, 1.0, 0.95}, {0.0, 1.0, 0.95})};
  EXPECT_EQ(PlaceLegend(spec), LegendPlace::kTopLeft);
  // Filled along the top: the bottom right is empty.
  spec.series.push_back(Points({0.1, 0.5}, {0.9, 0.9}));
  EXPECT_EQ(PlaceLegend(spec), LegendPlace::kBottomRight);
  // Nothing anywhere near the top right: it is the first choice.
  spec.series = {Points({0.0, 0.1, 1.0}, {1.0, 0.0, 0.0})};
  EXPECT_EQ(PlaceLegend(spec), LegendPlace::kTopRight);
}

TEST(PlaceLegend, ALineCountsAlongItsLengthAndLogAxesTheirLogarithm) {
  PlotSpec spec;
  // A diagonal from the bottom left to the top right crosses both corners it joins.
  spec.series = {{"line", {0.0, 1.0}, {0.0, 1.0}, SeriesStyle::kLine, {}}};
  EXPECT_EQ(PlaceLegend(spec), LegendPlace::kTopLeft);
  // 1, 100 and 1000 on a log axis sit at 0, 2/3 and 1: 100 is in the top third, where on a
  // linear axis it is in the bottom one.
  PlotSpec log;
  log.series = {Points({0.0, 1.0, 0.5, 1.0}, {1000.0, 1000.0, 100.0, 1.0})};
  EXPECT_EQ(PlaceLegend(log), LegendPlace::kTopCentre);
  log.log_y = true;
  EXPECT_EQ(PlaceLegend(log), LegendPlace::kBottomLeft);
}

}  // namespace
}  // namespace uwscan::viewer
