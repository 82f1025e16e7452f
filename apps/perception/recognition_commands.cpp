#include "apps/perception/recognition_commands.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apps/cli/data_cache.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/output_path.hpp"
#include "apps/cli/pose_option.hpp"
#include "apps/cli/progress_bar.hpp"
#include "apps/cli/reference_options.hpp"
#include "apps/perception/recognition_json.hpp"
#include "mapping/reconstruction/scan_file.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "perception/recognition/object_catalogue.hpp"
#include "perception/recognition/object_database_builder.hpp"
#include "perception/recognition/object_recognizer.hpp"
#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::app {
namespace {

struct BuildDbArgs {
  std::vector<std::string> objects;
  std::string output;
  std::string scanner;
  int views = 48;
  std::vector<double> standoffs_m = {0.6, 1.0, 1.4};
  double voxel_m = 0.005;
  std::string units = "m";
  std::uint64_t seed = 1;
  int threads = 0;
};

void RunBuildDb(const BuildDbArgs& a) {
  std::vector<std::filesystem::path> inputs(a.objects.begin(), a.objects.end());
  inputs.push_back(a.scanner);
  CheckOutputPath(a.output, "-o", inputs);
  std::vector<perception::ObjectSource> sources;
  for (const std::string& name : a.objects) {
    if (!std::filesystem::exists(name)) {
      sources.push_back(perception::CatalogueObject(name));
    } else if (perception::IsCloudFile(name)) {
      sources.push_back(perception::CloudObject(name, UnitsToMetres(a.units)));
    } else {
      sources.push_back(perception::MeshObject(name, UnitsToMetres(a.units)));
    }
  }
  const scanner::Scanner scanner = a.scanner.empty()
                                       ? scanner::DefaultScanner(scanner::ScannerKind::kGalvo)
                                       : scanner::LoadScanner(a.scanner);
  scanner::sim::VirtualScannerOptions scan_options;
  scan_options.pattern.kind = scanner.kind();
  scan_options.table_cache = TableCache();
  const scanner::sim::VirtualScanner virtual_scanner(scanner, scan_options);
  perception::DatabaseBuildOptions options;
  options.views = a.views;
  options.standoffs_m = a.standoffs_m;
  options.parameters.voxel_m = a.voxel_m;
  options.parameters.normal_radius_m = 2.5 * a.voxel_m;
  options.parameters.feature_radius_m = 5.0 * a.voxel_m;
  options.parameters.scanner = a.scanner.empty() ? "default galvanometer scanner" : a.scanner;
  options.seed = a.seed;
  options.threads = a.threads;
  ProgressBar progress;
  const perception::ObjectDatabase db = perception::BuildObjectDatabase(
      sources, virtual_scanner, options,
      [&](double fraction) { progress.Update("scanning views", fraction); });
  db.Save(a.output);
  std::printf("%s: %zu objects\n", a.output.c_str(), db.objects.size());
  for (const std::string& name : a.objects) {
    const std::filesystem::path sidecar = perception::GraspSidecarPath(name);
    if (std::filesystem::exists(name) && !std::filesystem::exists(sidecar)) {
      std::printf("  %s: no %s beside it, so no grasp frames (recognize gives its pose only)\n",
                  name.c_str(), sidecar.filename().c_str());
    }
  }
  for (const perception::ObjectModel& o : db.objects) {
    std::string symmetries;
    for (const perception::SymmetryAxis& s : o.symmetries) {
      symmetries +=
          (symmetries.empty() ? "" : ", ") +
          (s.continuous() ? std::string("continuous") : std::to_string(s.order) + "-fold");
    }
    std::printf(
        "  %-14s %3zu views, diameter %.3f m, %zu model points, %zu grasps, symmetries: %s%s\n",
        o.id.c_str(), o.views.size(), o.diameter_m, o.model.size(), o.grasps.size(),
        symmetries.empty() ? "none" : symmetries.c_str(),
        o.symmetries_declared ? " (declared)" : "");
  }
}

struct RecognizeArgs {
  std::string scan, db, json;
  std::string units = "m";
  std::vector<double> viewpoint;
  std::uint64_t seed = 1;
  int threads = 0;
  std::optional<int> sweep;
};

// `path` as seen from the folder `file` is in.
std::string RelativeToFolderOf(const std::string& path, const std::string& file) {
  const std::filesystem::path folder = std::filesystem::absolute(file).parent_path();
  return std::filesystem::absolute(path)
      .lexically_normal()
      .lexically_relative(folder.lexically_normal())
      .string();
}

void RunRecognize(const RecognizeArgs& a) {
  if (!a.json.empty()) CheckOutputPath(a.json, "--json", {a.scan, a.db});
  mapping::ReconstructionOptions log_options;
  log_options.table_cache = TableCache();
  log_options.sweep = a.sweep;
  mapping::ScanFrame frame;
  frame.metres_per_unit = UnitsToMetres(a.units);
  if (!a.viewpoint.empty()) frame.T_file_sensor = ParsePoseOption(a.viewpoint, "--viewpoint", true);
  const mapping::ScanFile file = mapping::ReadScanFile(a.scan, log_options, frame);
  const perception::PointCloud& scan = file.cloud;
  const perception::ObjectDatabase db = perception::ObjectDatabase::Load(a.db);
  perception::RecognitionOptions options;
  options.seed = a.seed;
  options.threads = a.threads;
  const perception::RecognitionResult result = perception::RecognizeObjects(scan, db, options);
  if (file.rows_in_file != scan.size()) {
    std::printf("%zu of the file's %zu points dropped: a NaN or infinite coordinate or normal\n",
                file.rows_in_file - scan.size(), file.rows_in_file);
  }
  if (!file.T_file_sensor.matrix().isIdentity(0.0)) {
    const Eigen::Vector3d at = file.T_file_sensor.translation();
    std::printf(
        "sensor at (%g, %g, %g) %s in the file's frame (%s); positions below are in the "
        "sensor's frame, metres (--json: T_file_O in the file's)\n",
        at.x(), at.y(), at.z(), a.units.c_str(),
        file.viewpoint == mapping::ViewpointSource::kGiven ? "--viewpoint"
                                                           : "the file's VIEWPOINT");
  }
  std::printf("%zu points, %zu on planes, %zu segments\n", scan.size(), result.plane_points,
              result.objects.size());
  for (const perception::RecognizedObject& o : result.objects) {
    const Eigen::Vector3d t = o.T_S_O.translation();
    if (o.object_id == "unknown") {
      std::printf("  unknown        %6zu points at (%.3f, %.3f, %.3f) m\n", o.segment.size(),
                  o.centroid_S.x(), o.centroid_S.y(), o.centroid_S.z());
      continue;
    }
    std::printf(
        "  %-14s %6zu points, score %.2f, chi2 %.3f (margin %.3f), at (%.4f, %.4f, %.4f) m, "
        "%zu free directions, %zu grasps\n",
        o.object_id.c_str(), o.segment.size(), o.score, o.chi_square, o.margin, t.x(), t.y(), t.z(),
        o.free_directions.size(), o.grasps_S.size());
    if (!o.equivalent_poses_S.empty()) {
      std::printf("    %zu other pose%s fit as well (--json: equivalent_poses)\n",
                  o.equivalent_poses_S.size(), o.equivalent_poses_S.size() > 1 ? "s" : "");
    }
    for (const auto& [id, T_S_O] : o.equivalent_objects_S) {
      std::printf("    or %s: the scan fits it as well\n", id.c_str());
    }
  }
  if (!a.json.empty()) {
    nlohmann::json j = RecognitionJson(result, file);
    if (a.sweep) j["scan_sweep"] = *a.sweep;
    // Relative to the report's folder, so the viewer finds them from anywhere.
    j["scan"] = RelativeToFolderOf(a.scan, a.json);
    j["database"] = RelativeToFolderOf(a.db, a.json);
    WriteJsonFile(a.json, j);
  }
}

}  // namespace

void AddBuildDbCommand(CLI::App& app) {
  auto a = std::make_shared<BuildDbArgs>();
  CLI::App* cmd = app.add_subcommand(
      "build-db",
      "scan objects with the virtual scanner and write the database `recognize` searches: "
      "ESF per view, model with FPFH, diameter, symmetries, grasp frames");
  cmd->add_option(
         "objects", a->objects,
         "mesh files (PLY/OFF/STL/OBJ in --units; grasps and symmetries from "
         "MESH.grasps.yaml beside them), scans of objects (PCD/XYZ, PLY without faces: "
         "a cloud, taught as its points' surface) or procedural objects: pipe, elbow, tee, flange, "
         "valve_wheel, valve_lever, panel")
      ->required();
  cmd->add_option("-o,--output", a->output, "object database to write")->required();
  cmd->add_option("--views", a->views, "views per object over the sphere of directions")
      ->capture_default_str()
      ->check(CLI::Range(1, 10000));
  cmd->add_option("--standoff-m", a->standoffs_m, "camera distances used in turn, metres")
      ->capture_default_str();
  cmd->add_option("--scanner", a->scanner, "scanner file (default: the galvanometer scanner)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--voxel", a->voxel_m, "voxel of views, models and scans, metres")
      ->capture_default_str()
      ->check(kPositiveNumber);
  cmd->add_option("--units", a->units,
                  "units of the mesh and cloud files' coordinates: m, cm or mm (CAD exports are "
                  "often in mm)")
      ->capture_default_str()
      ->check(CLI::IsMember({"m", "cm", "mm"}));
  cmd->add_option("--seed", a->seed, "scan noise and ESF sampling seed")->capture_default_str();
  cmd->add_option("--threads", a->threads, "threads (0: all)")->check(kNonNegativeNumber);
  cmd->callback([a] { RunBuildDb(*a); });
}

void AddRecognizeCommand(CLI::App& app) {
  auto a = std::make_shared<RecognizeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "recognize",
      "find the database's objects in a scan (sensor frame): id, pose, free directions, "
      "covariance, grasp poses");
  cmd->add_option("scan", a->scan,
                  "PLY, PCD or XYZ cloud, or a dive log (one sweep, placed with its navigation "
                  "when it has some)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--sweep", a->sweep,
                  "the sweep of a dive log of several to recognise objects in");
  cmd->add_option("--db", a->db, "object database from `uwscan build-db`")->required();
  cmd->add_option("--units", a->units,
                  "unit of the cloud file's coordinates: m, cm or mm (many range scans are in mm)")
      ->capture_default_str()
      ->check(kReferenceUnits);
  cmd->add_option("--viewpoint", a->viewpoint,
                  "the sensor's pose in the cloud file's frame, in its units: tx ty tz qx qy qz "
                  "qw, or tx ty tz (default: the PCD's VIEWPOINT, else the file's origin)")
      ->expected(3, 7);
  cmd->add_option("--json", a->json, "write every object, candidate and grasp as JSON");
  cmd->add_option("--seed", a->seed, "RANSAC and ESF seed");
  cmd->add_option("--threads", a->threads, "threads (0: all)")->check(kNonNegativeNumber);
  cmd->callback([a] { RunRecognize(*a); });
}

}  // namespace uwscan::app
