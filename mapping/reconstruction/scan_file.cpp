#include "mapping/reconstruction/scan_file.hpp"

#include "mapping/log/dive_log.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping {

perception::PointCloud ReadScanFile(const std::filesystem::path& path, ReconstructionOptions options) {
  if (path.extension() != ".db") return perception::ReadCloud(path);
  const DiveLogReader log(path);
  options.use_navigation = false;
  const Reconstruction r = Reconstruct(log, options);
  if (r.points.empty()) throw Error(path.string() + ": the dive log holds no triangulated point");
  return perception::MakeCloud(r.points);
}

}  // namespace uwscan::mapping
