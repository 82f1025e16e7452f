#include "ros/conversions/navigation_input.hpp"

#include "scanner/common/error.hpp"

namespace uwscan::ros {
namespace {

// North-east-down from east-north-up: x_ned = y_enu, y_ned = x_enu, z_ned = -z_enu.
Eigen::Matrix3d NedFromEnu() {
  Eigen::Matrix3d R;
  R << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  return R;
}

// Forward-right-down from forward-left-up (and back: the matrix is its own inverse).
Eigen::Matrix3d FrdFromFlu() { return Eigen::Vector3d(1, -1, -1).asDiagonal(); }

}  // namespace

NavigationSource ParseNavigationSource(const std::string& text, const std::string& what) {
  if (text == "odometry") return NavigationSource::kOdometry;
  if (text == "tf") return NavigationSource::kTf;
  throw Error(what + ": '" + text + "', expected odometry or tf");
}

NavigationAxes ParseNavigationAxes(const std::string& text, const std::string& what) {
  if (text == "ned") return NavigationAxes::kNedFrd;
  if (text == "enu") return NavigationAxes::kEnuFlu;
  throw Error(what + ": '" + text + "', expected ned (NED world, forward-right-down vehicle) or " +
              "enu (ENU world, forward-left-up vehicle)");
}

std::string ToString(NavigationSource source) {
  return source == NavigationSource::kTf ? "tf" : "odometry";
}

std::string ToString(NavigationAxes axes) {
  return axes == NavigationAxes::kEnuFlu ? "enu" : "ned";
}

Eigen::Isometry3d VehiclePoseInUwscanAxes(const Eigen::Isometry3d& T_odom_base,
                                          NavigationAxes axes) {
  if (axes == NavigationAxes::kNedFrd) return T_odom_base;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = NedFromEnu() * T_odom_base.linear() * FrdFromFlu();
  T.translation() = NedFromEnu() * T_odom_base.translation();
  return T;
}

Eigen::Isometry3d MountInUwscanAxes(const Eigen::Isometry3d& T_base_camera, NavigationAxes axes) {
  if (axes == NavigationAxes::kNedFrd) return T_base_camera;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = FrdFromFlu() * T_base_camera.linear();
  T.translation() = FrdFromFlu() * T_base_camera.translation();
  return T;
}

Eigen::Isometry3d VehiclePoseInNavigationAxes(const Eigen::Isometry3d& T_W_V, NavigationAxes axes) {
  if (axes == NavigationAxes::kNedFrd) return T_W_V;
  // Both matrices are their own inverses.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = NedFromEnu() * T_W_V.linear() * FrdFromFlu();
  T.translation() = NedFromEnu() * T_W_V.translation();
  return T;
}

Eigen::Vector3d WorldPointInNavigationAxes(const Eigen::Vector3d& p_W, NavigationAxes axes) {
  return axes == NavigationAxes::kNedFrd ? p_W : Eigen::Vector3d(NedFromEnu() * p_W);
}

Covariance6d WorldCovarianceInNavigationAxes(const Covariance6d& c, NavigationAxes axes) {
  if (axes == NavigationAxes::kNedFrd) return c;
  Covariance6d B = Covariance6d::Zero();
  B.topLeftCorner<3, 3>() = NedFromEnu();
  B.bottomRightCorner<3, 3>() = NedFromEnu();
  return B * c * B.transpose();
}

std::optional<OdometryMessage> NavigationFromTransforms(
    const std::vector<TransformMessage>& transforms, const RosFrames& frames) {
  for (const TransformMessage& t : transforms) {
    if (t.header.frame_id != frames.odom || t.child_frame_id != frames.base_link) continue;
    OdometryMessage m;
    m.header = t.header;
    m.child_frame_id = t.child_frame_id;
    m.pose = t.transform;
    return m;
  }
  return std::nullopt;
}

}  // namespace uwscan::ros
