#include "bench/robustness/reader_probes.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "mapping/change/change_report.hpp"
#include "mapping/log/dive_log.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "perception/features/descriptor_database.hpp"
#include "perception/recognition/object_database.hpp"
#include "ros/bridge/bag_file.hpp"
#include "scanner/calibration/calibration_dataset.hpp"
#include "scanner/calibration/calibration_scene.hpp"
#include "scanner/calibration/opencv_camera_import.hpp"
#include "scanner/common/atomic_file.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"
#include "scanner/common/triangle_mesh.hpp"
#include "scanner/lasers/scan_pattern.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/scene.hpp"
#include "viewer/scene/map_report.hpp"
#include "viewer/scene/recognition_report.hpp"
#include "viewer/scene/tum_trajectory.hpp"

namespace uwscan::bench {
namespace {

namespace fs = std::filesystem;

std::size_t ReadCloudFile(const fs::path& path) { return perception::ReadCloud(path).size(); }

std::size_t ReadMeshFile(const fs::path& path) {
  const scanner::TriangleMesh mesh = scanner::LoadMesh(path);
  return mesh.vertices.size() + mesh.triangles.size();
}

std::size_t ReadDiveLog(const fs::path& path) {
  const mapping::DiveLogReader log(path);
  std::size_t items = 0;
  log.ForEachFrame([&](const mapping::FrameRecord&, const mapping::GroundTruthRecord*) { ++items; },
                   /*with_truth=*/true);
  items += log.ReadNavigation().size();
  if (log.vehicle_mount()) ++items;
  return items;
}

std::size_t ReadScene(const fs::path& path) {
  const scanner::sim::Scene scene = scanner::sim::LoadScene(path);
  return scene.objects.size() + 1;
}

std::size_t ReadCalibrationManifest(const fs::path& path) {
  // The manifest is read from its folder; the fuzzed file is that folder's manifest.yaml.
  const scanner::calibration::CalibrationDataset dataset =
      scanner::calibration::LoadCalibrationDataset(path.parent_path());
  return dataset.views.size() + dataset.planes.size();
}

// A ROS bag read as `uwscan bag import` reads one: its topics, then every message of every topic
// (the types uwscan reads; a bag with another type is refused).
std::size_t ReadBag(const fs::path& path) {
  const ros::BagReader reader(path.string());
  std::vector<std::string> topics;
  for (const ros::BagTopic& topic : reader.Topics()) topics.push_back(topic.name);
  std::size_t messages = 0;
  ros::BagVisitor visitor;
  visitor.image = [&](const std::string&, ros::ImageMessage&&) { ++messages; };
  visitor.odometry = [&](const std::string&, ros::OdometryMessage&&) { ++messages; };
  visitor.transforms = [&](const std::string&, std::vector<ros::TransformMessage>&&) {
    ++messages;
  };
  visitor.text = [&](const std::string&, ros::StringMessage&&) { ++messages; };
  reader.Read(topics, visitor);
  return messages;
}

std::vector<ReaderProbe> MakeProbes() {
  using scanner::calibration::ImportOpenCvCalibration;
  return {
      {"cloud_ply", ".ply", ReadCloudFile},
      {"cloud_pcd", ".pcd", ReadCloudFile},
      {"cloud_xyz", ".xyz", ReadCloudFile},
      {"mesh_off", ".off", ReadMeshFile},
      {"mesh_stl", ".stl", ReadMeshFile},
      {"mesh_obj", ".obj", ReadMeshFile},
      {"mesh_ply", ".ply", ReadMeshFile},
      {"scene_yaml", ".yaml", ReadScene},
      {"scanner_yaml", ".yaml",
       [](const fs::path& path) {
         scanner::LoadScanner(path);
         return std::size_t{1};
       }},
      {"scan_pattern_yaml", ".yaml",
       [](const fs::path& path) {
         return static_cast<std::size_t>(
             scanner::ParseScanPattern(ReadFileBytes(path), path.string()).frames_per_sweep());
       }},
      {"calibration_scene_yaml", ".yaml",
       [](const fs::path& path) {
         scanner::calibration::LoadCalibrationScene(path);
         return std::size_t{1};
       }},
      {"calibration_manifest", "manifest.yaml", ReadCalibrationManifest},
      {"calibration_truth", ".yaml",
       [](const fs::path& path) {
         const auto truth = scanner::calibration::LoadDatasetTruth(path);
         return truth.T_C_O_views.size() + truth.T_C_O_planes.size();
       }},
      {"opencv_intrinsics", ".yaml",
       [](const fs::path& path) {
         ImportOpenCvCalibration(path);
         return std::size_t{1};
       }},
      {"dive_log", ".uwlog", ReadDiveLog},
      {"object_database", ".db",
       [](const fs::path& path) { return perception::ObjectDatabase::Load(path).objects.size(); }},
      {"descriptor_database", ".esfdb",
       [](const fs::path& path) { return perception::DescriptorDatabase::Load(path).size(); }},
      {"map_report", ".json",
       [](const fs::path& path) { return viewer::ReadMapReport(path).trajectories.size(); }},
      {"recognition_report", ".json",
       [](const fs::path& path) { return viewer::ReadRecognitionReport(path).objects.size(); }},
      {"change_deviations", ".ply",
       [](const fs::path& path) { return mapping::ReadDeviationsPly(path).points.size(); }},
      {"tum_trajectory", ".tum",
       [](const fs::path& path) { return viewer::ReadTumTrajectory(path).size(); }},
      {"bag", ".bag", ReadBag},
  };
}

}  // namespace

const std::vector<ReaderProbe>& ReaderProbes() {
  static const std::vector<ReaderProbe> probes = MakeProbes();
  return probes;
}

void PrepareReaderWorkspace(const fs::path& workspace, const fs::path& data_dir) {
  fs::create_directories(workspace / "scanners");
  fs::create_directories(workspace / "inputs");
  for (const fs::directory_entry& entry : fs::directory_iterator(data_dir / "scanners")) {
    fs::copy_file(entry.path(), workspace / "scanners" / entry.path().filename(),
                  fs::copy_options::overwrite_existing);
  }
  const cv::Mat image(24, 32, CV_8UC1, cv::Scalar(90));
  for (const char* name : {"v0.png", "v1.png", "v2.png"}) {
    if (!cv::imwrite((workspace / "inputs" / name).string(), image)) {
      throw Error("cannot write '" + (workspace / "inputs" / name).string() + "'");
    }
  }
}

fs::path ReaderInputPath(const ReaderProbe& probe, const fs::path& workspace) {
  const bool whole_name = !probe.extension.empty() && probe.extension.front() != '.';
  return workspace / "inputs" / (whole_name ? probe.extension : "input" + probe.extension);
}

const ReaderProbe& FindReaderProbe(const std::string& name) {
  std::ostringstream names;
  for (const ReaderProbe& probe : ReaderProbes()) {
    if (probe.name == name) return probe;
    names << ' ' << probe.name;
  }
  throw Error("no reader called '" + name + "' (readers:" + names.str() + ")");
}

}  // namespace uwscan::bench
