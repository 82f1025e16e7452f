#include "perception/recognition/view_pose_hypotheses.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <numbers>
#include <optional>

#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

struct Outline {
  Eigen::Vector3d centroid;    // in the cloud's sensor frame
  Eigen::Vector3d sight;       // unit, from the sensor to the centroid
  Eigen::Vector3d major_axis;  // unit, across the line of sight
};

// Centroid, line of sight and the principal axis of the points projected across that line.
std::optional<Outline> OutlineOf(const PointCloud& cloud) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < cloud.size(); ++i) centroid += cloud.Point(i);
  centroid /= static_cast<double>(cloud.size());
  if (!(centroid.norm() > 1e-9)) return std::nullopt;
  const Eigen::Vector3d sight = centroid.normalized();
  const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - sight * sight.transpose();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d d = across * (cloud.Point(i) - centroid);
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
  Eigen::Vector3d major = eigen.eigenvectors().col(2);
  // One point or a line along the sight: any direction across it will do.
  if (!(eigen.eigenvalues()(2) > 0.0)) major = sight.unitOrthogonal();
  return Outline{centroid, sight, (across * major).normalized()};
}

}  // namespace

std::vector<Eigen::Isometry3d> ViewPoseHypotheses(const PointCloud& segment_S,
                                                  const ObjectView& view, int rolls) {
  if (rolls < 1) throw Error("ViewPoseHypotheses: rolls must be >= 1");
  if (segment_S.empty() || view.cloud.empty()) {
    throw Error("ViewPoseHypotheses: the segment and the view need points");
  }
  const std::optional<Outline> seen = OutlineOf(segment_S);
  const std::optional<Outline> stored = OutlineOf(view.cloud);
  if (!seen || !stored) return {};
  // The view's line of sight turned onto the segment's, then its major axis rolled onto the
  // segment's (signed angle about the segment's line of sight).
  const Eigen::Matrix3d R_sight =
      Eigen::Quaterniond::FromTwoVectors(stored->sight, seen->sight).toRotationMatrix();
  const Eigen::Vector3d axis = R_sight * stored->major_axis;
  const double first_roll =
      std::atan2(axis.cross(seen->major_axis).dot(seen->sight), axis.dot(seen->major_axis));
  std::vector<Eigen::Isometry3d> starts;
  for (int k = 0; k < rolls; ++k) {
    const double roll = first_roll + 2.0 * std::numbers::pi * k / rolls;
    Eigen::Isometry3d T_S_C = Eigen::Isometry3d::Identity();
    T_S_C.linear() = Eigen::AngleAxisd(roll, seen->sight).toRotationMatrix() * R_sight;
    T_S_C.translation() = seen->centroid - T_S_C.linear() * stored->centroid;
    starts.push_back(view.T_O_C * T_S_C.inverse());
  }
  return starts;
}

}  // namespace uwscan::perception
