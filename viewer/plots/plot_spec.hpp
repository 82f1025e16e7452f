#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "viewer/scene/colour_map.hpp"

// A chart described in plain data (no VTK): what `uwscan plot` draws.
namespace uwscan::viewer {

enum class SeriesStyle { kPoints, kLine, kBars };

struct PlotSeries {
  std::string label;  // in the legend
  std::vector<double> x, y;
  SeriesStyle style = SeriesStyle::kPoints;
  Rgb colour;
};

struct PlotSpec {
  std::string title, x_label, y_label;
  bool log_x = false, log_y = false;  // points <= 0 on a log axis are left out
  std::vector<PlotSeries> series;
  // Bar charts: the names under the bars at x = 1, 2, ...
  std::vector<std::string> x_tick_labels;
  // A fixed y axis (e.g. 0 to 1 for rates); std::nullopt: fitted to the points.
  std::optional<std::pair<double, double>> y_range;
};

// Indices of the points no other point beats in both coordinates (smaller x and smaller y are
// better; negate a coordinate where larger is better), sorted by x: the Pareto front. Points
// with a non-finite coordinate are never on it.
std::vector<std::size_t> ParetoFront(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace uwscan::viewer
