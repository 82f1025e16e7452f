#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "mapping/slam/dive_mapping.hpp"
#include "mapping/slam/joint_pose_uncertainty.hpp"
#include "mapping/slam/pose_graph.hpp"
#include "perception/cloud/point_cloud.hpp"

namespace uwscan::mapping {

// What one epoch of a structure is known from.
enum class SurveyKind {
  kDesign,  // an as-built or design model (a mesh): exact, sampled on its surface
  kCloud,   // a point cloud from another tool or sensor: its own error unknown
  kMap      // a uwscan map (its report, or a dive log mapped): its poses' covariance known
};
const char* ToString(SurveyKind kind);

// One epoch, in the world frame (metres), ready to compare.
struct Survey {
  std::string name;  // the file it came from, for messages and reports
  SurveyKind kind = SurveyKind::kCloud;
  perception::PointCloud cloud;  // kDesign: surface samples with the faces' outward normals
  // kMap only: the submap poses (T_W_V) and their [rotation, position] covariances (the
  // rotation about the pose's position, pose_graph.hpp), as the map report lists them.
  std::vector<Eigen::Isometry3d> poses;
  std::vector<Matrix6d> pose_covariances;
  // kMap, when known: how well the poses are placed relative to each other (their joint
  // covariance on demand); null when the report does not carry it.
  std::shared_ptr<const JointPoseUncertainty> joint_uncertainty;
};

struct SurveyReadOptions {
  double units_to_m = 1.0;  // the file's unit in metres (a CAD model in millimetres: 0.001), > 0
  double design_spacing_m =
      0.004;               // a mesh is sampled with one point per this spacing squared of area, > 0
  std::uint64_t seed = 1;  // of the surface sampling
  void Check() const;
};

// Reads one epoch:
// - .json: a `uwscan map --json` report: the map file it names, its SLAM poses and their
//   covariances;
// - a mesh: .obj, .stl, .off, or .ply holding faces: a design model, sampled on its surface;
// - a cloud: .pcd, .xyz, or .ply without faces.
// Throws uwscan::Error naming the file when it is missing or malformed, a report is not a map
// report or lacks the covariances, a PLY declares faces but holds none, or a mesh's area would
// take more than 50 million samples at the spacing asked.
Survey ReadSurvey(const std::filesystem::path& path, const SurveyReadOptions& options = {});

// A dive log mapped (MapDive) as an epoch, as its map report would give it: its map, its SLAM
// poses and their covariances. `name` names the log. Throws uwscan::Error when the mapping has
// no covariances.
Survey SurveyOfDive(const DiveMapping& mapping, const std::string& name);

// The position uncertainty, along `normal_W`, of a point placed by the survey's pose nearest to
// it (std, metres): n^T J C J^T n with J = [-[p - t]x, I] for the pose's position t and
// covariance C. 0 for a survey without poses.
double PoseSigmaAlongNormal(const Survey& survey, const Eigen::Vector3d& p_W,
                            const Eigen::Vector3d& normal_W);

}  // namespace uwscan::mapping
