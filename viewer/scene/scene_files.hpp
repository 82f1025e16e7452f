#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "mapping/reconstruction/reconstruction.hpp"
#include "viewer/scene/map_report.hpp"
#include "viewer/scene/scene.hpp"
#include "viewer/scene/tum_trajectory.hpp"

// Files into the viewer's scene. Every reader is the project's own: clouds through
// perception::ReadCloud, meshes through scanner::LoadMesh, dive logs through mapping::Reconstruct.
namespace uwscan::viewer {

enum class FileKind {
  kCloud,
  kMesh,
  kTrajectory,
  kDiveLog,
  kMapReport,
  kRecognitionReport,
  kChangeReport
};
const char* ToString(FileKind kind);

// What a file holds, from its extension and, where one extension has two meanings, its first
// bytes: .pcd .xyz clouds; .ply a mesh when its header declares faces, else a cloud; .off .stl
// .obj meshes; .txt .tum trajectories; .db .uwlog dive logs (SQLite); .json map, recognition and
// change reports (by their "kind"). Throws
// uwscan::Error naming the file when it is missing or of none of these kinds.
FileKind KindOfFile(const std::filesystem::path& path);

// A cloud file as a layer named after the file.
void AddCloudFile(const std::filesystem::path& path, Scene& scene);
// A mesh file, in its own coordinates.
void AddMeshFile(const std::filesystem::path& path, Scene& scene);
// A TUM trajectory file as a line through its positions.
void AddTrajectoryFile(const std::filesystem::path& path, Scene& scene);

TrajectoryLayer TrajectoryFromPoses(const std::string& name, const std::vector<StampedPose>& poses);

// What a dive log adds and what it took to get there.
struct DiveLogSummary {
  std::size_t points = 0;
  std::int64_t frames = 0;
  bool world_frame = false;  // placed with the log's navigation
  bool has_truth = false;    // a simulated log: error per point and the true camera path
  double truth_mean_error_m = 0.0;
};

// A dive log's reconstructed cloud (with each point's distance to its true surface point when
// the log is simulated), the camera path its navigation reports and, when simulated, the true
// camera path. Throws uwscan::Error naming the log when it cannot be read or gives no point.
DiveLogSummary AddDiveLog(const std::filesystem::path& path,
                          const mapping::ReconstructionOptions& options, Scene& scene);

// Whatever KindOfFile says the file is (map reports with `map_drawing`; dive logs, also those a
// recognition report names, triangulated with `log_options`).
void AddFile(const std::filesystem::path& path, const mapping::ReconstructionOptions& log_options,
             const MapReportDrawing& map_drawing, Scene& scene);

}  // namespace uwscan::viewer
