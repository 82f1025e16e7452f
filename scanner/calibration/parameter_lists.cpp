#include "scanner/calibration/parameter_lists.hpp"

#include <cmath>

namespace uwscan::scanner::calibration {
namespace {

// Componentwise standard deviation of a vector moved along directions a and b by independent
// amounts of standard deviations sa and sb.
Eigen::Vector3d Spread(const Eigen::Vector3d& a, double sa, const Eigen::Vector3d& b, double sb) {
  return ((sa * a).cwiseAbs2() + (sb * b).cwiseAbs2()).cwiseSqrt();
}

void AddVector(const std::string& name, const Eigen::Vector3d& value, const Eigen::Vector3d& std,
               std::vector<ParameterEstimate>* out) {
  const char* axis[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) out->push_back({name + "_" + axis[i], value[i], std[i]});
}

}  // namespace

std::vector<ParameterEstimate> CameraParameters(const PinholeCamera& c, const IntrinsicsResult* s) {
  return {
      {"fx_px", c.fx_px, s ? s->fx_std : 0.0},      {"fy_px", c.fy_px, s ? s->fy_std : 0.0},
      {"cx_px", c.cx_px, s ? s->cx_std : 0.0},      {"cy_px", c.cy_px, s ? s->cy_std : 0.0},
      {"k1", c.k1, s ? s->distortion_std[0] : 0.0}, {"k2", c.k2, s ? s->distortion_std[1] : 0.0},
      {"p1", c.p1, s ? s->distortion_std[2] : 0.0}, {"p2", c.p2, s ? s->distortion_std[3] : 0.0},
      {"k3", c.k3, s ? s->distortion_std[4] : 0.0}};
}

std::vector<ParameterEstimate> ViewportParameters(const std::string& key, const FlatViewport& v,
                                                  const ViewportStds& s) {
  // A unit normal tilted by an angle of std s moves each component by at most s.
  const Eigen::Vector3d normal_std =
      (Eigen::Vector3d::Ones() - v.normal.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt() * s.normal_rad;
  std::vector<ParameterEstimate> out;
  AddVector(key + ".normal", v.normal, normal_std, &out);
  out.push_back({key + ".distance_m", v.distance_m, s.distance_m});
  out.push_back({key + ".thickness_m", v.thickness_m, s.thickness_m});
  return out;
}

std::vector<ParameterEstimate> GalvoLaserParameters(const GalvoLaser& laser,
                                                    const GalvoLaserStdDevs* s) {
  const Eigen::Matrix3d R_L = laser.T_C_L.linear();
  const Eigen::Matrix3d R_M = laser.T_C_M.linear();
  std::vector<ParameterEstimate> out;
  Eigen::Vector3d position_std = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal_std = Eigen::Vector3d::Zero();
  Eigen::Vector3d mirror_position_std = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis_std = Eigen::Vector3d::Zero();
  if (s != nullptr) {
    for (int j = 0; j < 3; ++j) {
      position_std += (s->laser_position_m[j] * R_L.col(j)).cwiseAbs2();
    }
    position_std = position_std.cwiseSqrt();
    // Turning {L} about x_L moves z_L along y_L; about y_L, along x_L.
    normal_std =
        Spread(R_L.col(1), s->laser_rotation_rad.x(), R_L.col(0), s->laser_rotation_rad.y());
    mirror_position_std =
        Spread(R_M.col(0), s->mirror_position_m.x(), R_M.col(2), s->mirror_position_m.y());
    // Tilting y_M about x_M moves it along z_M; about z_M, along x_M.
    axis_std = Spread(R_M.col(2), s->mirror_axis_rad.x(), R_M.col(0), s->mirror_axis_rad.y());
  }
  AddVector("laser.emitter_m", laser.T_C_L.translation(), position_std, &out);
  AddVector("laser.plane_normal", R_L.col(2), normal_std, &out);
  AddVector("laser.mirror_origin_m", laser.T_C_M.translation(), mirror_position_std, &out);
  AddVector("laser.mirror_axis", R_M.col(1), axis_std, &out);
  out.push_back({"laser.mirror_step_rad", laser.mirror_step_rad, s ? s->mirror_step_rad : 0.0});
  out.push_back(
      {"laser.rotation_distance_m", laser.rotation_distance_m, s ? s->rotation_distance_m : 0.0});
  return out;
}

}  // namespace uwscan::scanner::calibration
