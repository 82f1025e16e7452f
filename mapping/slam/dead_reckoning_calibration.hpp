#pragma once

#include <Eigen/Geometry>
#include <cmath>

// The dead reckoning's systematic errors, as a DVL makes them: the speed it measures is
// (1 + scale_error) times the true one, and its velocity is turned by misalignment_rad about
// the down axis (a DVL mounted a little askew). Both stay constant over a dive, so their effect
// grows with the distance travelled, not with its square root: modelled as noise per motion
// they would make the graph overconfident. The pose graph estimates them with the poses
// instead (pose_graph.hpp), and the mapper places new frames with the corrected navigation.
namespace uwscan::mapping {

struct DeadReckoningCalibration {
  double scale_error = 0.0;       // measured speed / true speed - 1
  double misalignment_rad = 0.0;  // of the measured velocity, about the down axis

  // A dead-reckoned displacement made true: its horizontal part (x, y) turned back by the
  // misalignment and divided by the scale, its vertical part (from pressure) kept. Valid in the
  // world frame and in a level vehicle frame (the turn is about the down axis in both).
  template <typename T>
  static Eigen::Matrix<T, 3, 1> Correct(const Eigen::Matrix<T, 3, 1>& displacement,
                                        const T& scale_error, const T& misalignment_rad) {
    using std::cos;
    using std::sin;
    const T c = cos(misalignment_rad);
    const T s = sin(misalignment_rad);
    const T inverse_scale = T(1) / (T(1) + scale_error);
    Eigen::Matrix<T, 3, 1> out;
    out << inverse_scale * (c * displacement.x() + s * displacement.y()),
        inverse_scale * (-s * displacement.x() + c * displacement.y()), displacement.z();
    return out;
  }

  Eigen::Vector3d Correct(const Eigen::Vector3d& displacement) const {
    return Correct<double>(displacement, scale_error, misalignment_rad);
  }

  // A dead-reckoned motion T_a_b with its translation corrected (in a's frame, taken level:
  // roll and pitch of a few milliradians change the correction by their square).
  Eigen::Isometry3d CorrectMotion(const Eigen::Isometry3d& T_a_b) const {
    Eigen::Isometry3d out = T_a_b;
    out.translation() = Correct(T_a_b.translation());
    return out;
  }
};

}  // namespace uwscan::mapping
