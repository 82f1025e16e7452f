#include "mapping/reconstruction/scan_file.hpp"

#include <numeric>
#include <string>

#include "mapping/log/dive_log.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

std::string SweepRange(const std::vector<int>& sweeps) {
  if (sweeps.empty()) return "no sweep";
  if (sweeps.size() == 1) return "only sweep " + std::to_string(sweeps.front());
  return std::to_string(sweeps.size()) + " sweeps, " + std::to_string(sweeps.front()) + " to " +
         std::to_string(sweeps.back());
}

}  // namespace

ScanFile ReadScanFile(const std::filesystem::path& path, ReconstructionOptions options) {
  ScanFile scan;
  if (path.extension() != ".db") {
    if (options.sweep) {
      throw Error(path.string() + ": a sweep (" + std::to_string(*options.sweep) +
                  ") is chosen from a dive log, this is a cloud file");
    }
    perception::CloudReadStats stats;
    scan.cloud = perception::ReadCloud(path, &stats);
    scan.rows = std::move(stats.rows);
    scan.rows_in_file = stats.num_in_file;
    return scan;
  }
  const DiveLogReader log(path);
  options.use_navigation = true;
  options.relative_to_middle = true;
  const Reconstruction r = Reconstruct(log, options);
  if (!options.sweep && r.sweeps.size() > 1) {
    throw Error(path.string() + ": the dive log holds " + SweepRange(r.sweeps) +
                "; recognition takes one: choose it with --sweep");
  }
  if (options.sweep && r.frames == 0) {
    throw Error(path.string() + ": the dive log has no sweep " + std::to_string(*options.sweep) +
                " (it holds " + SweepRange(r.sweeps) + ")");
  }
  if (r.points.empty()) {
    const std::string what = options.sweep
                                 ? "sweep " + std::to_string(*options.sweep) + " of the dive log"
                                 : std::string("the dive log");
    throw Error(path.string() + ": " + what + " holds no triangulated point");
  }
  scan.cloud = perception::MakeCloud(r.points);
  scan.rows.resize(r.points.size());
  std::iota(scan.rows.begin(), scan.rows.end(), std::size_t{0});
  scan.rows_in_file = r.points.size();
  return scan;
}

}  // namespace uwscan::mapping
