#pragma once

#include <filesystem>
#include <vector>

#include "viewer/plots/plot_spec.hpp"

namespace uwscan::viewer {

// Draws the plots side by side (VTK charts, offscreen) into one RGB PNG of the given size,
// written atomically. Throws uwscan::Error when there is no X display, no plot, a plot has no
// point it can draw, or the file cannot be written.
void SavePlotsPng(const std::vector<PlotSpec>& plots, const std::filesystem::path& png_path,
                  int width_px, int height_px);

}  // namespace uwscan::viewer
