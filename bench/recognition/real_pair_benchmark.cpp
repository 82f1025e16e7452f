#include "bench/recognition/real_pair_benchmark.hpp"

#include <chrono>
#include <vector>

#include "bench/recognition/real_pair_pcl.hpp"
#include "mapping/reconstruction/scan_file.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "perception/recognition/object_catalogue.hpp"
#include "perception/recognition/object_database_builder.hpp"
#include "perception/recognition/object_recognizer.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/virtual_scanner.hpp"

namespace uwscan::bench {
namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::filesystem::path Required(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) {
    throw Error("real recognition pair: " + path.string() +
                " is missing: run scripts/fetch_data.sh");
  }
  return path;
}

// As `uwscan build-db MODEL` teaches a cloud: the default galvanometer scanner, default views.
perception::ObjectDatabase Teach(const std::filesystem::path& model, const RealPairOptions& o) {
  const scanner::Scanner scanner = scanner::DefaultScanner(scanner::ScannerKind::kGalvo);
  scanner::sim::VirtualScannerOptions scan_options;
  scan_options.pattern.kind = scanner.kind();
  scan_options.table_cache = o.table_cache;
  const scanner::sim::VirtualScanner virtual_scanner(scanner, scan_options);
  perception::DatabaseBuildOptions build;
  build.seed = o.seed;
  build.threads = o.threads;
  const std::vector<perception::ObjectSource> sources = {perception::CloudObject(model)};
  return perception::BuildObjectDatabase(sources, virtual_scanner, build);
}

// As `uwscan recognize SCENE --db ...` answers: the pose of the segment recognised as the model.
std::optional<Eigen::Isometry3d> Recognise(const perception::PointCloud& scene,
                                           const perception::ObjectDatabase& db,
                                           const RealPairOptions& o) {
  perception::RecognitionOptions options;
  options.seed = o.seed;
  options.threads = o.threads;
  const perception::RecognitionResult result = perception::RecognizeObjects(scene, db, options);
  for (const perception::RecognizedObject& object : result.objects) {
    if (object.object_id == db.objects.front().id) return object.T_S_O;
  }
  return std::nullopt;
}

}  // namespace

void RealPairOptions::Check() const {
  OptionChecks("RealPairOptions").AtLeast("threads", threads, 1);
}

RealPairFigures RunRealPairBench(const RealPairOptions& o) {
  o.Check();
  RealPairFigures f;
  f.model = "milk.pcd";
  f.scene = "milk_cartoon_all_small_clorox.pcd";
  const std::filesystem::path model_path = Required(o.data_cache / "scans" / f.model);
  const std::filesystem::path scene_path = Required(o.data_cache / "scans" / f.scene);

  Clock::time_point start = Clock::now();
  const perception::ObjectDatabase db = Teach(model_path, o);
  f.database_seconds = Since(start);
  const perception::PointCloud scene = mapping::ReadScanFile(scene_path).cloud;
  start = Clock::now();
  f.uwscan.T_scene_model = Recognise(scene, db, o);
  f.uwscan.seconds = Since(start);

  const perception::PointCloud model = perception::ReadCloud(model_path);
  start = Clock::now();
  f.pcl.T_scene_model = PclCorrespondenceGrouping(model, scene, o.threads);
  f.pcl.seconds = Since(start);

  if (f.uwscan.T_scene_model && f.pcl.T_scene_model) {
    const Eigen::Isometry3d& a = *f.uwscan.T_scene_model;
    const Eigen::Isometry3d& b = *f.pcl.T_scene_model;
    f.rotation_difference_rad = Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
    f.translation_difference_m = (a * model.origin - b * model.origin).norm();
  }
  return f;
}

}  // namespace uwscan::bench
