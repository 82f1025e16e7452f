#pragma once

#include <Eigen/Core>
#include <vector>

#include "scanner/lasers/projection_functions.hpp"
#include "scanner/triangulation/light_plane.hpp"

namespace uwscan::scanner {

// The scan pattern of seed 001 Sec. II-B: n lines of m equidistant waypoints inside the FoV
// limits on the projection plane (eqs. 7-10), line i at constant p_x (vertical lines in the
// camera image), voltages from the inverse functions f5, f6 (eq. 11), and per line the plane
// fitted to its waypoints p_ij and the points lambda further along their beams (eqs. 12-14).
struct MemsScanPatternOptions {
  int lines = 50;                  // n, >= 1
  int waypoints_per_line = 50;     // m, >= 2
  double fov_fraction_x = 0.9;     // share of the FoV width used, (0, 1]
  double fov_fraction_y = 0.9;     // share of the FoV height used, (0, 1]
  double plane_extension_m = 1.0;  // lambda of eq. 12, metres, non-zero (either sign)

  // Throws uwscan::Error naming the field when a value is unusable.
  void Check() const;
};

struct MemsLine {
  std::vector<Eigen::Vector2d> p_P;    // waypoints on the projection plane, metres
  std::vector<Eigen::Vector2d> volts;  // their voltage pairs
  Plane plane_C;                       // the line's light plane in water, camera frame
  double plane_rms_m = 0.0;  // rms distance of the 2m fitted points to it: how far the beams
                             // at the waypoints are from one plane (the mirror's path between
                             // waypoints adds to this; see mirror_dynamics.hpp)
};

// Lines ordered by p_x (ascending), waypoints by p_y (ascending). The FoV is shrunk about its
// centre by the fractions; with one line, the line runs through the centre. Throws
// uwscan::Error when options fail Check(), when a waypoint needs voltages outside the
// calibrated drive range (the rectangle reaches into a corner the beam cannot; lower the
// fractions), or when a line's points do not span a plane.
std::vector<MemsLine> DesignMemsScanPattern(const ProjectionFunctions& functions,
                                            const MemsScanPatternOptions& options);

// The light plane of a line the mirror is driven along at `volts` (its waypoints' voltage pairs),
// as `functions` say those voltages send the beam: each beam from its point on the projection
// plane (f1, f2) along its direction in water, fitted by one plane. What a later calibration
// makes of lines designed and driven with an earlier one. Throws uwscan::Error naming the line
// (`line` in messages) when a voltage pair lies outside the range `functions` were fitted on
// (they would be extrapolated) or its beam does not leave the viewport.
Plane MemsLinePlaneAt(const ProjectionFunctions& functions,
                      const std::vector<Eigen::Vector2d>& volts, double plane_extension_m,
                      int line);

}  // namespace uwscan::scanner
