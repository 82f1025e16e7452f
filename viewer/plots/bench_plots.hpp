#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "viewer/plots/plot_spec.hpp"

namespace uwscan::viewer {

// The charts of one bench's JSON (`uwscan bench NAME --json FILE`), each a trade-off a person
// reads in seconds: triangulation methods and stripe detectors as accuracy against time with
// their Pareto front and the speed limit measured in the same run; registration pipelines as
// success against time; the MEMS waypoints per line (plane residual, lines/s) and the plane
// residual against range; calibration steps as time per step; the deformation experiment as
// fit residual against incidence; the viewer bench as render time against points; long dives
// as time per submap and memory against dive time.
struct BenchPlots {
  std::string bench;  // which bench wrote the file
  std::vector<PlotSpec> plots;
};

// Throws uwscan::Error naming the file when it is not JSON or not the output of a bench this
// version can draw.
BenchPlots ReadBenchPlots(const std::filesystem::path& json_path);

}  // namespace uwscan::viewer
