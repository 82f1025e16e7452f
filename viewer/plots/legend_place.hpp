#pragma once

#include "viewer/plots/plot_spec.hpp"

namespace uwscan::viewer {

// Where a chart's legend hides least of its data.
enum class LegendPlace { kTopRight, kTopLeft, kTopCentre, kBottomRight, kBottomLeft };

// The third of the plot, across and up or down, holding the fewest of the spec's points, on the
// axes' own scales (log where the spec says so): markers count once, lines at 32 samples per
// segment, bars along their height from zero. Ties go to the earlier place in LegendPlace's
// order. Plain data, no VTK: ChartPng anchors the legend there.
LegendPlace PlaceLegend(const PlotSpec& spec);

}  // namespace uwscan::viewer
