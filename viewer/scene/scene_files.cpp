#include "viewer/scene/scene_files.hpp"

#include <algorithm>
#include <cctype>

#include "mapping/log/dive_log.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/ply_reader.hpp"
#include "scanner/common/triangle_mesh.hpp"
#include "viewer/scene/change_report.hpp"
#include "viewer/scene/recognition_report.hpp"

namespace uwscan::viewer {
namespace {

namespace fs = std::filesystem;

std::string Extension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// The camera's path in {W} as the navigation reports it (vehicle pose times the camera mount).
TrajectoryLayer NavigationPath(const mapping::DiveLogReader& log) {
  const Eigen::Isometry3d T_V_C = log.vehicle_mount().value_or(Eigen::Isometry3d::Identity());
  TrajectoryLayer layer;
  layer.name = log.path().filename().string() + " navigation";
  for (const mapping::NavigationRecord& r : log.ReadNavigation()) {
    layer.times_s.push_back(r.time_s);
    layer.positions_W.push_back((r.T_W_V * T_V_C).translation());
  }
  return layer;
}

TrajectoryLayer TruePath(const mapping::DiveLogReader& log) {
  TrajectoryLayer layer;
  layer.name = log.path().filename().string() + " truth";
  log.ForEachFrame(
      [&layer](const mapping::FrameRecord& frame, const mapping::GroundTruthRecord* truth) {
        if (truth == nullptr) return;
        layer.times_s.push_back(frame.time_s);
        layer.positions_W.push_back(truth->T_W_C.translation());
      },
      /*with_truth=*/true);
  return layer;
}

}  // namespace

const char* ToString(FileKind kind) {
  switch (kind) {
    case FileKind::kCloud:
      return "cloud";
    case FileKind::kMesh:
      return "mesh";
    case FileKind::kTrajectory:
      return "trajectory";
    case FileKind::kDiveLog:
      return "dive log";
    case FileKind::kMapReport:
      return "map report";
    case FileKind::kRecognitionReport:
      return "recognition report";
    case FileKind::kChangeReport:
      return "change report";
  }
  return "?";
}

FileKind KindOfFile(const fs::path& path) {
  if (!fs::is_regular_file(path)) throw Error(path.string() + ": no such file");
  const std::string ext = Extension(path);
  if (ext == ".pcd" || ext == ".xyz") return FileKind::kCloud;
  if (ext == ".ply")
    return scanner::PlyFaceCount(path).value_or(0) > 0 ? FileKind::kMesh : FileKind::kCloud;
  if (ext == ".off" || ext == ".stl" || ext == ".obj") return FileKind::kMesh;
  if (ext == ".txt" || ext == ".tum") return FileKind::kTrajectory;
  if (ext == ".db" || ext == ".uwlog") return FileKind::kDiveLog;
  if (ext == ".json") {
    if (IsMapReport(path)) return FileKind::kMapReport;
    if (IsRecognitionReport(path)) return FileKind::kRecognitionReport;
    if (IsChangeReport(path)) return FileKind::kChangeReport;
    throw Error(path.string() +
                ": a JSON file that is not a map, recognition or change report (\"kind\": "
                "\"map_report\", \"recognition_report\" or \"change_report\"); bench reports "
                "are drawn by `uwscan plot`");
  }
  throw Error(path.string() +
              ": unknown kind of file (clouds .ply .pcd .xyz, meshes .ply .off .stl .obj, "
              "trajectories .txt .tum, dive logs .db, map and recognition reports .json)");
}

void AddCloudFile(const fs::path& path, Scene& scene) {
  const perception::PointCloud cloud = perception::ReadCloud(path);
  CloudLayer layer;
  layer.name = path.filename().string();
  layer.origin = cloud.origin;
  layer.points = cloud.points;
  layer.intensity = cloud.intensity;
  scene.clouds.push_back(std::move(layer));
}

void AddMeshFile(const fs::path& path, Scene& scene) {
  MeshLayer layer;
  layer.name = path.filename().string();
  layer.mesh = scanner::LoadMesh(path);
  scene.meshes.push_back(std::move(layer));
}

TrajectoryLayer TrajectoryFromPoses(const std::string& name,
                                    const std::vector<StampedPose>& poses) {
  TrajectoryLayer layer;
  layer.name = name;
  for (const StampedPose& pose : poses) {
    layer.times_s.push_back(pose.time_s);
    layer.positions_W.push_back(pose.T_W_B.translation());
  }
  return layer;
}

void AddTrajectoryFile(const fs::path& path, Scene& scene) {
  scene.trajectories.push_back(
      TrajectoryFromPoses(path.filename().string(), ReadTumTrajectory(path)));
}

DiveLogSummary AddDiveLog(const fs::path& path, const mapping::ReconstructionOptions& options,
                          Scene& scene) {
  const mapping::DiveLogReader log(path);
  const mapping::Reconstruction r = mapping::Reconstruct(log, options);
  if (r.points.empty()) throw Error(path.string() + ": no frame gave a point; nothing to show");
  DiveLogSummary summary;
  summary.points = r.points.size();
  summary.frames = r.frames;
  summary.world_frame = r.world_frame;
  summary.has_truth = r.truth.size() == r.points.size();
  if (const std::optional<mapping::TruthError> e = mapping::CompareToTruth(r))
    summary.truth_mean_error_m = e->mean_m;

  CloudLayer layer;
  layer.name = path.filename().string();
  const perception::PointCloud cloud = perception::MakeCloud(r.points);
  layer.origin = cloud.origin;
  layer.points = cloud.points;
  if (summary.has_truth) {
    layer.error_m.reserve(r.points.size());
    for (std::size_t i = 0; i < r.points.size(); ++i) {
      layer.error_m.push_back(
          static_cast<float>((r.points[i] - r.truth[i]).norm()));  // NaN: no truth
    }
  }
  scene.clouds.push_back(std::move(layer));
  // The paths are only in the cloud's frame when the cloud was placed with navigation.
  if (r.world_frame) {
    TrajectoryLayer navigation = NavigationPath(log);
    if (!navigation.positions_W.empty()) scene.trajectories.push_back(std::move(navigation));
    if (summary.has_truth) {
      TrajectoryLayer truth = TruePath(log);
      if (!truth.positions_W.empty()) scene.trajectories.push_back(std::move(truth));
    }
  }
  return summary;
}

void AddFile(const fs::path& path, const mapping::ReconstructionOptions& log_options,
             const MapReportDrawing& map_drawing, Scene& scene) {
  switch (KindOfFile(path)) {
    case FileKind::kCloud:
      return AddCloudFile(path, scene);
    case FileKind::kMesh:
      return AddMeshFile(path, scene);
    case FileKind::kTrajectory:
      return AddTrajectoryFile(path, scene);
    case FileKind::kDiveLog:
      AddDiveLog(path, log_options, scene);
      return;
    case FileKind::kMapReport:
      return AddMapReport(ReadMapReport(path), map_drawing, scene);
    case FileKind::kRecognitionReport:
      return AddRecognitionReport(ReadRecognitionReport(path), log_options, scene);
    case FileKind::kChangeReport:
      return AddChangeReport(path, scene);
  }
}

}  // namespace uwscan::viewer
