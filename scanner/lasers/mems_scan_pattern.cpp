#include "scanner/lasers/mems_scan_pattern.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner {
namespace {

// Position k of `count` equidistant positions across [lo, hi] shrunk about its centre by
// `fraction`; the centre itself when count == 1.
double Spread(int k, int count, double lo, double hi, double fraction) {
  const double centre = 0.5 * (lo + hi);
  if (count == 1) return centre;
  const double half = 0.5 * fraction * (hi - lo);
  return centre + half * (2.0 * k / (count - 1) - 1.0);
}

// How far outside the calibrated drive range a waypoint may fall, as a share of the range:
// at the FoV edges f5, f6 return the limit voltages only to their fitting error.
constexpr double kDriveRangeSlack = 1e-3;

}  // namespace

void MemsScanPatternOptions::Check() const {
  const OptionChecks check("MemsScanPatternOptions");
  check.AtLeast("lines", lines, 1);
  check.AtLeast("waypoints_per_line", waypoints_per_line, 2);
  check.InRange("fov_fraction_x", fov_fraction_x, 0.0, 1.0, Interval::kOpenLow);
  check.InRange("fov_fraction_y", fov_fraction_y, 0.0, 1.0, Interval::kOpenLow);
  check.Require(std::isfinite(plane_extension_m) && plane_extension_m != 0.0, "plane_extension_m",
                "a finite non-zero value (metres)", plane_extension_m);
}

std::vector<MemsLine> DesignMemsScanPattern(const ProjectionFunctions& functions,
                                            const MemsScanPatternOptions& options) {
  options.Check();
  functions.Check();
  const FovLimits fov = functions.Fov();
  const double slack = kDriveRangeSlack * (functions.volts_max - functions.volts_min).maxCoeff();
  const int m = options.waypoints_per_line;
  std::vector<MemsLine> lines(static_cast<std::size_t>(options.lines));
  for (int i = 0; i < options.lines; ++i) {
    MemsLine& line = lines[static_cast<std::size_t>(i)];
    const double p_x =
        Spread(i, options.lines, fov.p_min_m.x(), fov.p_max_m.x(), options.fov_fraction_x);
    std::vector<Eigen::Vector3d> points_C;
    points_C.reserve(2 * static_cast<std::size_t>(m));
    for (int j = 0; j < m; ++j) {
      const Eigen::Vector2d p(
          p_x, Spread(j, m, fov.p_min_m.y(), fov.p_max_m.y(), options.fov_fraction_y));
      const Eigen::Vector2d volts = functions.VoltsAt(p);
      const RayTrace beam = functions.RayInWater_C(volts);
      if (!functions.InDriveRange(volts, slack) || !beam.ok()) {
        std::ostringstream message;
        message << "scan pattern: waypoint " << j << " of line " << i << " at p_P = ("
                << p.transpose() << ") m needs volts (" << volts.transpose()
                << "), outside the calibrated range [" << functions.volts_min.transpose()
                << "] .. [" << functions.volts_max.transpose()
                << "]; lower fov_fraction_x / fov_fraction_y";
        throw Error(message.str());
      }
      line.p_P.push_back(p);
      line.volts.push_back(volts);
      // Eq. 12: the waypoint on the plane and its partner lambda along the beam. The beam
      // starts on the projection plane at f1, f2 (volts), which is p only to the fit error
      // of f5, f6 against f1, f2; p_ij is the designed point the seed fits through.
      const Eigen::Vector3d p_C = functions.T_C_P * Eigen::Vector3d(p.x(), p.y(), 0.0);
      points_C.push_back(p_C);
      points_C.push_back(p_C + options.plane_extension_m * beam.ray.direction);
    }
    PlaneFit fit;
    try {
      fit = FitPlane(points_C);
    } catch (const Error& e) {
      throw Error("scan pattern: line " + std::to_string(i) + ": " + e.what());
    }
    line.plane_C = fit.plane;
    line.plane_rms_m = fit.rms_m;
  }
  return lines;
}

Plane MemsLinePlaneAt(const ProjectionFunctions& functions,
                      const std::vector<Eigen::Vector2d>& volts, double plane_extension_m,
                      int line) {
  functions.Check();
  const double slack = kDriveRangeSlack * (functions.volts_max - functions.volts_min).maxCoeff();
  std::vector<Eigen::Vector3d> points_C;
  points_C.reserve(2 * volts.size());
  for (std::size_t j = 0; j < volts.size(); ++j) {
    if (!functions.InDriveRange(volts[j], slack)) {
      std::ostringstream message;
      message << "scan pattern: line " << line << ", waypoint " << j << " is driven at ("
              << volts[j].transpose() << ") V, outside the range ["
              << functions.volts_min.transpose() << "] .. [" << functions.volts_max.transpose()
              << "] V the projection functions were calibrated on (they would be extrapolated)";
      throw Error(message.str());
    }
    const RayTrace beam = functions.RayInWater_C(volts[j]);
    if (!beam.ok()) {
      throw Error("scan pattern: line " + std::to_string(line) + ", waypoint " + std::to_string(j) +
                  ": the calibrated beam does not leave the viewport");
    }
    const Eigen::Vector2d p = functions.PointAt(volts[j]);
    const Eigen::Vector3d p_C = functions.T_C_P * Eigen::Vector3d(p.x(), p.y(), 0.0);
    points_C.push_back(p_C);
    points_C.push_back(p_C + plane_extension_m * beam.ray.direction);
  }
  try {
    return FitPlane(points_C).plane;
  } catch (const Error& e) {
    throw Error("scan pattern: line " + std::to_string(line) + ": " + e.what());
  }
}

}  // namespace uwscan::scanner
