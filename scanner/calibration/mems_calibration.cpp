#include "scanner/calibration/mems_calibration.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner::calibration {
namespace {

using VoltsKey = std::pair<double, double>;

VoltageLine FitLine(const Eigen::Vector2d& volts, const std::vector<Eigen::Vector3d>& points) {
  VoltageLine line;
  line.volts = volts;
  line.points = static_cast<int>(points.size());
  for (const Eigen::Vector3d& p : points) line.point_C += p;
  line.point_C /= static_cast<double>(points.size());
  Eigen::MatrixXd centred(points.size(), 3);
  for (size_t i = 0; i < points.size(); ++i)
    centred.row(static_cast<Eigen::Index>(i)) = (points[i] - line.point_C).transpose();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeThinV);
  line.direction_C = svd.matrixV().col(0);
  // Away from the scanner: the farther points lie deeper in the camera frame.
  if (line.direction_C.z() < 0.0) line.direction_C = -line.direction_C;
  double sum2 = 0.0;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d d = p - line.point_C;
    sum2 += (d - d.dot(line.direction_C) * line.direction_C).squaredNorm();
  }
  line.rms_m = std::sqrt(sum2 / static_cast<double>(points.size()));
  return line;
}

// The projection plane: normal along the beam of the voltage pair nearest to zero volts,
// crossing it at `depth_m`; x_P along the camera's x projected onto the plane.
Eigen::Isometry3d ProjectionPlane(const std::vector<VoltageLine>& lines, double depth_m) {
  const VoltageLine& centre =
      *std::min_element(lines.begin(), lines.end(), [](const VoltageLine& a, const VoltageLine& b) {
        return a.volts.squaredNorm() < b.volts.squaredNorm();
      });
  const Eigen::Vector3d z = centre.direction_C;
  const double t = (depth_m - centre.point_C.z()) / z.z();
  Eigen::Vector3d x = Eigen::Vector3d::UnitX() - z.x() * z;
  x.normalize();
  Eigen::Isometry3d T_C_P = Eigen::Isometry3d::Identity();
  T_C_P.linear().col(0) = x;
  T_C_P.linear().col(1) = z.cross(x);
  T_C_P.linear().col(2) = z;
  T_C_P.translation() = centre.point_C + t * z;
  return T_C_P;
}

}  // namespace

void MemsCalibrationOptions::Check() const {
  const OptionChecks check("MemsCalibrationOptions");
  check.InRange("degree", degree, 1, 8);
  check.AtLeast("projection_plane_depth_m", projection_plane_depth_m, 0.0, "m (0 = automatic)");
  check.AtLeast("min_planes_per_pair", min_planes_per_pair, 2);
}

namespace {

// q_kl: where each dot's camera ray meets its plane, by voltage pair, and the depths they span.
struct DotPoints {
  std::map<VoltsKey, std::vector<Eigen::Vector3d>> points_of;
  double depth_min = 1e300, depth_max = -1e300;
  int dots = 0;
};

DotPoints PointsOfDots(const RefractiveCamera& camera, const std::vector<Plane>& planes_C,
                       const std::vector<std::vector<DotObservation>>& dots) {
  DotPoints out;
  for (size_t l = 0; l < planes_C.size(); ++l) {
    std::map<VoltsKey, int> seen;
    for (const DotObservation& dot : dots[l]) {
      if (!dot.volts.allFinite() || !dot.dot_px.allFinite()) {
        throw Error("MEMS calibration: " + dot.image + ": voltages or dot position not finite");
      }
      const VoltsKey key{dot.volts.x(), dot.volts.y()};
      if (++seen[key] > 1) {
        throw Error("MEMS calibration: plane " + std::to_string(l) + " has two dots for volts (" +
                    std::to_string(key.first) + ", " + std::to_string(key.second) + ")");
      }
      const RayTrace ray = camera.PixelToRayInWater(dot.dot_px);
      const RayHit hit = ray.ok() ? IntersectRayPlane(ray.ray, planes_C[l]) : RayHit{};
      if (!hit.ok()) {
        throw Error("MEMS calibration: " + dot.image + ": the camera ray of the dot misses plane " +
                    std::to_string(l));
      }
      out.points_of[key].push_back(hit.point);
      out.depth_min = std::min(out.depth_min, hit.point.z());
      out.depth_max = std::max(out.depth_max, hit.point.z());
      ++out.dots;
    }
  }
  return out;
}

}  // namespace

MemsCalibrationResult CalibrateMemsProjection(const RefractiveCamera& camera,
                                              const std::vector<Plane>& planes_C,
                                              const std::vector<std::vector<DotObservation>>& dots,
                                              const MemsCalibrationOptions& options) {
  options.Check();
  if (planes_C.size() != dots.size()) {
    throw Error("MEMS calibration: " + std::to_string(planes_C.size()) + " planes but dots for " +
                std::to_string(dots.size()));
  }
  if (planes_C.size() < 2)
    throw Error("MEMS calibration: needs dots on at least 2 planes, got " +
                std::to_string(planes_C.size()));
  const DotPoints seen = PointsOfDots(camera, planes_C, dots);
  const std::map<VoltsKey, std::vector<Eigen::Vector3d>>& points_of = seen.points_of;
  MemsCalibrationResult result;
  result.dots = seen.dots;
  const double depth_min = seen.depth_min, depth_max = seen.depth_max;
  // A line per voltage pair seen on enough planes (seed eq. 18).
  double sum2 = 0.0;
  int fitted = 0;
  for (const auto& [key, points] : points_of) {
    if (static_cast<int>(points.size()) < options.min_planes_per_pair) {
      ++result.skipped_pairs;
      continue;
    }
    result.lines.push_back(FitLine(Eigen::Vector2d(key.first, key.second), points));
    sum2 += result.lines.back().rms_m * result.lines.back().rms_m * points.size();
    fitted += static_cast<int>(points.size());
  }
  const int terms = (options.degree + 1) * (options.degree + 2) / 2;
  if (static_cast<int>(result.lines.size()) < terms) {
    throw Error("MEMS calibration: " + std::to_string(result.lines.size()) +
                " voltage pairs seen on >= " + std::to_string(options.min_planes_per_pair) +
                " planes; a degree-" + std::to_string(options.degree) + " fit needs at least " +
                std::to_string(terms));
  }
  result.line_rms_m = std::sqrt(sum2 / fitted);

  const double depth = options.projection_plane_depth_m > 0.0 ? options.projection_plane_depth_m
                                                              : 0.5 * (depth_min + depth_max);
  const Eigen::Isometry3d T_C_P = ProjectionPlane(result.lines, depth);
  const Eigen::Isometry3d T_P_C = T_C_P.inverse();
  std::vector<Eigen::Vector2d> volts, p_P;
  std::vector<Eigen::Vector3d> v_P;
  for (const VoltageLine& line : result.lines) {
    const Eigen::Vector3d d_P = T_P_C.linear() * line.direction_C;
    const Eigen::Vector3d o_P = T_P_C * line.point_C;
    if (!(d_P.z() > 1e-6)) {
      throw Error("MEMS calibration: the beam of volts (" + std::to_string(line.volts.x()) + ", " +
                  std::to_string(line.volts.y()) + ") runs along the projection plane");
    }
    const Eigen::Vector3d on_plane = o_P - (o_P.z() / d_P.z()) * d_P;
    volts.push_back(line.volts);
    p_P.push_back(on_plane.head<2>());
    v_P.push_back(d_P);
  }
  const ProjectionFunctionFit fit = FitProjectionFunctions(volts, p_P, v_P, T_C_P, options.degree);
  result.functions = fit.functions;
  result.errors = fit.errors;
  return result;
}

}  // namespace uwscan::scanner::calibration
