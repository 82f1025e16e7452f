#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "scanner/common/triangle_mesh.hpp"
#include "viewer/scene/colour_map.hpp"

// What the viewer draws, in uwscan's own types (no VTK): the world frame {W} in metres.
namespace uwscan::viewer {

// A point cloud, stored like perception::PointCloud (float offsets from a double origin), with
// the per-point values it can be coloured by.
struct CloudLayer {
  std::string name;  // the file it came from, shown when a point is picked
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3f> points;  // metres, relative to origin
  std::vector<float> error_m;           // empty, or one per point: distance to truth (NaN: none)
  std::vector<float> intensity;         // empty, or one per point, the file's units
  // Empty, or one per point: signed deviation from a reference, metres (NaN: not significant).
  std::vector<float> deviation_m;
  std::vector<std::int32_t> object_ids;  // empty, or one per point (scene object; -1: none)

  std::size_t size() const { return points.size(); }
  Eigen::Vector3d Point(std::size_t i) const { return origin + points[i].cast<double>(); }
};

// A triangle mesh placed in the world (a model, or a recognised object where it was found).
struct MeshLayer {
  std::string name;
  scanner::TriangleMesh mesh;  // in its own frame {M}
  Eigen::Isometry3d T_W_M = Eigen::Isometry3d::Identity();
};

// A path of positions (navigation, truth, a SLAM estimate), drawn as a line.
struct TrajectoryLayer {
  std::string name;
  std::vector<double> times_s;               // one per position (may be empty)
  std::vector<Eigen::Vector3d> positions_W;  // metres
  std::optional<Rgb> colour;                 // default: a categorical colour by its index
};

// A position's uncertainty, drawn as the ellipsoid at `sigmas` standard deviations.
struct UncertaintyEllipsoid {
  Eigen::Vector3d centre_W = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance_m2 = Eigen::Matrix3d::Zero();  // symmetric positive semi-definite
  double sigmas = 3.0;
  Rgb colour{200, 200, 200};
};

// Text at a place in the world (a recognised object's name where it was found), drawn over
// the scene so that no surface hides it.
struct Label {
  Eigen::Vector3d position_W = Eigen::Vector3d::Zero();
  std::string text;
  Rgb colour{255, 255, 255};
};

// A coordinate frame (a grasp pose) drawn as three lines from its origin: x red, y green,
// z blue (the gripper's approach).
struct FrameAxes {
  std::string name;
  Eigen::Isometry3d T_W_F = Eigen::Isometry3d::Identity();
  double length_m = 0.05;  // > 0
};

struct Scene {
  std::vector<CloudLayer> clouds;
  std::vector<MeshLayer> meshes;
  std::vector<TrajectoryLayer> trajectories;
  std::vector<UncertaintyEllipsoid> ellipsoids;
  std::vector<Label> labels;
  std::vector<FrameAxes> frames;

  bool empty() const {
    return clouds.empty() && meshes.empty() && trajectories.empty() && ellipsoids.empty() &&
           labels.empty() && frames.empty();
  }
  std::size_t num_points() const;
  // A point of the scene near its middle (the first cloud's origin, else the first vertex or
  // position): the viewer renders relative to it so that float coordinates stay small.
  Eigen::Vector3d Anchor() const;
};

}  // namespace uwscan::viewer
