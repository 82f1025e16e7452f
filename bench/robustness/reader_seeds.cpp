#include "bench/robustness/reader_seeds.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "mapping/change/change_report.hpp"
#include "mapping/log/dive_log.hpp"
#include "mapping/log/dive_simulation.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "perception/features/descriptor_database.hpp"
#include "perception/recognition/object_database.hpp"
#include "ros/bag/bag_export.hpp"
#include "ros/bridge/bag_compression.hpp"
#include "scanner/calibration/calibration_dataset.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"
#include "scanner/common/triangle_mesh.hpp"
#include "scanner/lasers/scan_pattern.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"

namespace uwscan::bench {
namespace {

namespace fs = std::filesystem;

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out.flush()) throw Error("cannot write '" + path.string() + "'");
}

// A small cloud on a curved patch, with normals when asked.
perception::PointCloud SeedCloud(bool normals) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 5; ++j) points.emplace_back(0.01 * i, 0.01 * j, 1.0 + 0.001 * i * j);
  }
  perception::PointCloud cloud = perception::MakeCloud(points);
  if (normals) cloud.normals.assign(cloud.size(), Eigen::Vector3f(0.0f, 0.0f, -1.0f));
  return cloud;
}

scanner::TriangleMesh Tetrahedron() {
  scanner::TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}, {0, 0, 0.1}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return mesh;
}

void WriteMeshSeeds(const fs::path& folder) {
  const scanner::TriangleMesh mesh = Tetrahedron();
  std::string off = "OFF\n4 4 0\n", obj, stl = "solid seed\n";
  for (const Eigen::Vector3d& v : mesh.vertices) {
    const std::string xyz =
        std::to_string(v.x()) + " " + std::to_string(v.y()) + " " + std::to_string(v.z());
    off += xyz + "\n";
    obj += "v " + xyz + "\n";
  }
  for (const Eigen::Vector3i& t : mesh.triangles) {
    off += "3 " + std::to_string(t.x()) + " " + std::to_string(t.y()) + " " +
           std::to_string(t.z()) + "\n";
    obj += "f " + std::to_string(t.x() + 1) + " " + std::to_string(t.y() + 1) + " " +
           std::to_string(t.z() + 1) + "\n";
    stl += " facet normal 0 0 0\n  outer loop\n";
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d& v = mesh.vertices[std::size_t(t[k])];
      stl += "   vertex " + std::to_string(v.x()) + " " + std::to_string(v.y()) + " " +
             std::to_string(v.z()) + "\n";
    }
    stl += "  endloop\n endfacet\n";
  }
  stl += "endsolid seed\n";
  WriteText(folder / "mesh_off" / "seed_0.off", off);
  WriteText(folder / "mesh_obj" / "seed_0.obj", obj);
  WriteText(folder / "mesh_stl" / "seed_0.stl", stl);
  scanner::WriteMeshPly(mesh, folder / "mesh_ply" / "seed_0.ply");
}

void WriteDiveLogSeed(const fs::path& path) {
  mapping::DiveLogHeader header;
  header.scanner = scanner::DefaultScanner(scanner::ScannerKind::kGalvo);
  header.scan_pattern.kind = scanner::ScannerKind::kGalvo;
  header.navigation_noise = mapping::NavigationNoise{0.01, 0.001, 0.01, 0.002, 0.01, 0.001};
  header.producer = "uwscan bench robustness";
  fs::remove(path);
  mapping::DiveLogWriter writer(path, header);
  for (int i = 0; i < 3; ++i) {
    mapping::FrameRecord frame;
    frame.time_s = 0.01 * i;
    frame.command = i;
    frame.peaks_px = {{10.5 + i, 20.25}, {11.5, 21.0 + i}};
    mapping::GroundTruthRecord truth;
    truth.points_W = {{0.1, 0.2, 1.0}, {0.1, 0.21, 1.0}};
    truth.object_ids = {0, 1};
    if (i == 1)
      frame.image = mapping::LogImage{4, 3, mapping::LogPixelFormat::kMono8,
                                      std::vector<std::uint8_t>(12, 7)};
    writer.AppendFrame(frame, &truth);
    writer.AppendNavigation({0.01 * i, Eigen::Isometry3d(Eigen::Translation3d(0.1 * i, 0.0, 5.0))});
  }
  writer.SetVehicleMount(Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 0.3)));
}

void WriteObjectDatabaseSeed(const fs::path& path) {
  perception::ObjectDatabase db;
  perception::ObjectModel model;
  model.id = "seed";
  model.source = "bench robustness";
  model.model = SeedCloud(true);
  model.diameter_m = 0.08;
  perception::ObjectView view;
  view.cloud = SeedCloud(false);
  view.points = static_cast<int>(view.cloud.size());
  view.esf.setConstant(1.0f / 640.0f);
  model.views.push_back(view);
  model.grasps.push_back({"top", Eigen::Isometry3d::Identity()});
  db.objects.push_back(model);
  db.parameters.scanner = "galvo default";
  db.Save(path);
}

void WriteDescriptorDatabaseSeed(const fs::path& path) {
  perception::DescriptorDatabase db(8);
  const std::vector<float> a = {0.1f, 0.2f, 0.3f, 0.4f, 0.0f, 0.0f, 0.0f, 0.0f};
  const std::vector<float> b = {0.0f, 0.0f, 0.1f, 0.1f, 0.3f, 0.2f, 0.2f, 0.1f};
  db.Add("pipe", 0, a);
  db.Add("flange", 1, b);
  db.Save(path);
}

void WriteCalibrationSeeds(const fs::path& folder) {
  WriteText(folder / "calibration_manifest" / "seed_0.yaml",
            "uwscan_format: 1\ndataset: calibration\nstep: intrinsics\n"
            "pattern: {type: chessboard, columns: 9, rows: 6, square_m: 0.03}\n"
            "image_size: [32, 24]\n"
            "views: [{image: v0.png}, {image: v1.png}, {image: v2.png}]\n");
  scanner::calibration::DatasetTruth truth;
  truth.scanner = scanner::DefaultScanner(scanner::ScannerKind::kGalvo);
  truth.T_C_O_views = {Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 0.8))};
  truth.T_C_O_planes = {Eigen::Isometry3d(Eigen::Translation3d(0.05, 0.0, 1.0))};
  scanner::calibration::WriteDatasetTruth(folder / "calibration_truth" / "seed_0.yaml", truth);
  WriteText(folder / "opencv_intrinsics" / "seed_0.yaml",
            "%YAML:1.0\n---\nimage_width: 2048\nimage_height: 1088\n"
            "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
            "   data: [ 2400., 0., 1024., 0., 2400., 544., 0., 0., 1. ]\n"
            "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n"
            "   data: [ -0.1, 0.05, 0.001, -0.001, 0. ]\n");
  // The same in OpenCV's XML layout (read by content, whatever the file's name).
  WriteText(
      folder / "opencv_intrinsics" / "seed_1.yaml",
      "<?xml version=\"1.0\"?>\n<opencv_storage>\n<image_width>2048</image_width>\n"
      "<image_height>1088</image_height>\n<camera_matrix type_id=\"opencv-matrix\">\n  "
      "<rows>3</rows>\n"
      "  <cols>3</cols>\n  <dt>d</dt>\n  <data>\n    2400. 0. 1024. 0. 2400. 544. 0. 0. "
      "1.</data></camera_matrix>\n"
      "<distortion_coefficients type_id=\"opencv-matrix\">\n  <rows>5</rows>\n  <cols>1</cols>\n"
      "  <dt>d</dt>\n  <data>\n    -0.1 0.05 0.001 -0.001 0.</data></distortion_coefficients>\n"
      "</opencv_storage>\n");
}

void WriteReportSeeds(const fs::path& folder) {
  const std::string tum =
      "# t tx ty tz qx qy qz qw\n0.0 1 2 3 0 0 0 1\n0.5 1.1 2 3 0 0 0.0998334 0.9950042\n";
  WriteText(folder / "tum_trajectory" / "seed_0.tum", tum);
  std::string covariance = "[0.5";
  for (int i = 0; i < 36; ++i) covariance += i % 7 == 0 ? ", 0.0001" : ", 0";
  covariance += "]";
  WriteText(
      folder / "map_report" / "seed_0.json",
      "{\"uwscan_format\": 1, \"kind\": \"map_report\", \"log\": \"dive.db\",\n"
      " \"trajectories\": {\"slam\": [[0, 1, 2, 3, 0, 0, 0, 1], [0.5, 1.1, 2, 3, 0, 0, 0, 1]],\n"
      "                  \"dead_reckoning\": [[0, 1, 2, 3, 0, 0, 0, 1]]},\n"
      " \"pose_covariance\": [" +
          covariance +
          "],\n"
          " \"loops\": [{\"from_submap\": 0, \"to_submap\": 7, \"accepted\": true, \"reason\": "
          "\"\"}]}\n");
  const std::string pose =
      "{\"matrix\": [[1, 0, 0, 0.2], [0, 0, -1, 0.05], [0, 1, 0, 1.0], [0, 0, 0, 1]]}";
  WriteText(folder / "recognition_report" / "seed_0.json",
            "{\"uwscan_format\": 1, \"kind\": \"recognition_report\", \"scan\": \"scan.ply\",\n"
            " \"database\": \"objects.db\", \"scan_points\": 40,\n"
            " \"objects\": [{\"id\": \"valve_wheel\", \"segment\": [3, 4, 5, 9], \"centroid_m\": "
            "[0.2, 0.05, 1],\n"
            "   \"score\": 0.9, \"T_S_O\": " +
                pose +
                ",\n"
                "   \"grasps\": [{\"name\": \"rim\", \"matrix\": [[1, 0, 0, 0.2], [0, 1, 0, 0], "
                "[0, 0, 1, 0.9], [0, 0, 0, 1]]}]},\n"
                "  {\"id\": \"unknown\", \"segment\": [0, 1], \"centroid_m\": [0, 0, 1.2]}]}\n");
}

// What `uwscan compare -o` writes, for three core points: one changed (in region 0), one not,
// one not inspected.
void WriteDeviationSeeds(const fs::path& folder) {
  mapping::SurveyComparison c;
  for (int i = 0; i < 3; ++i) {
    mapping::CoreDeviation d;
    d.point_W = Eigen::Vector3d(0.01 * i, 0.0, 10.0);
    d.deviation_m = i == 2 ? NAN : 0.004 / (i + 1);
    d.lod_m = i == 2 ? NAN : 0.001;
    d.status = i == 0   ? mapping::SurfaceStatus::kChanged
               : i == 1 ? mapping::SurfaceStatus::kUnchanged
                        : mapping::SurfaceStatus::kNotInspected;
    c.deviations.push_back(d);
    c.region_of.push_back(i == 0 ? 0 : -1);
  }
  mapping::WriteDeviationsPly(folder / "change_deviations" / "seed_0.ply", c);
}

void RemoveLog(const fs::path& log) {
  for (const char* suffix : {"", "-wal", "-shm", "-journal"}) fs::remove(log.string() + suffix);
}

// One sweep of five frames of the short inspection dive: a bag of a few tens of KB, small enough
// for the fuzzers to mutate quickly.
void SimulateSeedDive(const fs::path& data_dir, const fs::path& log) {
  const fs::path scene_path = data_dir / "scenes" / "inspection_short.yaml";
  YAML::Node yaml = YAML::Load(ReadFileBytes(scene_path));
  yaml["scanner"]["sweeps"] = 1;
  yaml["scanner"]["galvo"]["step_stride"] = 50;
  YAML::Emitter emitter;
  emitter << yaml;
  const std::string text = emitter.c_str();
  const scanner::sim::Simulator simulator(
      scanner::sim::ParseScene(text, scene_path.string(), scene_path.parent_path()));
  mapping::DiveSimulationOptions options;
  options.threads =
      1;  // five frames: no use for OpenMP's threads in the process that forks the readers
  options.producer = "uwscan bench robustness";
  RemoveLog(log);
  mapping::SimulateDive(simulator, text, log, options);
}

// A simulated dive as `uwscan bag export` writes it (seed_0, uncompressed chunks), and the same bag
// with lz4 (seed_1) and bz2 (seed_2) chunks, as `rosbag record --lz4/--bz2` writes them.
void WriteBagSeeds(const fs::path& data_dir, const fs::path& folder) {
  const fs::path log = folder / "seed_dive.db";
  SimulateSeedDive(data_dir, log);
  const fs::path bag = folder / "seed_0.bag";
  for (const char* name : {"seed_0.bag", "seed_1.bag", "seed_2.bag"}) fs::remove(folder / name);
  ros::BagExportOptions options;
  options.producer = "uwscan bench robustness";
  ros::ExportToBag({log}, bag, options);
  RemoveLog(log);
  ros::WriteCompressedCopy(bag.string(), (folder / "seed_1.bag").string(),
                           ros::BagCompression::kLz4);
  ros::WriteCompressedCopy(bag.string(), (folder / "seed_2.bag").string(),
                           ros::BagCompression::kBz2);
}

}  // namespace

void WriteReaderSeeds(const fs::path& data_dir, const fs::path& folder) {
  for (const char* reader : {"cloud_ply",
                             "cloud_pcd",
                             "cloud_xyz",
                             "mesh_off",
                             "mesh_stl",
                             "mesh_obj",
                             "mesh_ply",
                             "scene_yaml",
                             "scanner_yaml",
                             "scan_pattern_yaml",
                             "calibration_scene_yaml",
                             "calibration_manifest",
                             "calibration_truth",
                             "opencv_intrinsics",
                             "dive_log",
                             "object_database",
                             "descriptor_database",
                             "map_report",
                             "recognition_report",
                             "change_deviations",
                             "tum_trajectory",
                             "bag"}) {
    fs::create_directories(folder / reader);
  }
  perception::WriteCloud(folder / "cloud_ply" / "seed_0.ply", SeedCloud(true), true);
  perception::WriteCloud(folder / "cloud_ply" / "seed_1.ply", SeedCloud(false), false);
  perception::WriteCloud(folder / "cloud_pcd" / "seed_0.pcd", SeedCloud(true), true);
  perception::WriteCloud(folder / "cloud_pcd" / "seed_1.pcd", SeedCloud(false), false);
  WriteText(folder / "cloud_xyz" / "seed_0.xyz",
            "# x y z\n0.1 0.2 1.0\n0.11 0.2 1.01 7\n\n0.12 0.21 1.0\n");
  WriteDeviationSeeds(folder);
  WriteMeshSeeds(folder);

  int n = 0;
  for (const char* scene :
       {"default.yaml", "inspection_short.yaml", "mems_plane.yaml", "camera_image.yaml"}) {
    fs::copy_file(data_dir / "scenes" / scene,
                  folder / "scene_yaml" / ("seed_" + std::to_string(n++) + ".yaml"),
                  fs::copy_options::overwrite_existing);
  }
  n = 0;
  for (const char* scene : {"calib_intrinsics.yaml", "calib_laser.yaml", "calib_mems.yaml"}) {
    fs::copy_file(data_dir / "scenes" / scene,
                  folder / "calibration_scene_yaml" / ("seed_" + std::to_string(n++) + ".yaml"),
                  fs::copy_options::overwrite_existing);
  }
  n = 0;
  for (const char* file : {"galvo_default.yaml", "mems_default.yaml"}) {
    fs::copy_file(data_dir / "scanners" / file,
                  folder / "scanner_yaml" / ("seed_" + std::to_string(n++) + ".yaml"),
                  fs::copy_options::overwrite_existing);
  }
  scanner::ScanPattern galvo, mems;
  mems.kind = scanner::ScannerKind::kMems;
  WriteText(folder / "scan_pattern_yaml" / "seed_0.yaml", scanner::ScanPatternToYaml(galvo));
  WriteText(folder / "scan_pattern_yaml" / "seed_1.yaml", scanner::ScanPatternToYaml(mems));

  WriteCalibrationSeeds(folder);
  WriteDiveLogSeed(folder / "dive_log" / "seed_0.uwlog");
  WriteObjectDatabaseSeed(folder / "object_database" / "seed_0.db");
  WriteDescriptorDatabaseSeed(folder / "descriptor_database" / "seed_0.esfdb");
  WriteReportSeeds(folder);
  WriteBagSeeds(data_dir, folder / "bag");
}

}  // namespace uwscan::bench
