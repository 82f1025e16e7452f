#include "scanner/lasers/mirror_dynamics.hpp"

#include <Eigen/LU>
#include <cmath>
#include <numbers>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner {
namespace {

// A continuous-time single-input single-output system x' = A x + B u, y = x[output].
struct StateSpace {
  Eigen::MatrixXd A;
  Eigen::VectorXd B;
  Eigen::Index output = 0;
};

// Appends a section driven by the current output (or by the external input when the system
// is still empty): first order (omega) or second order (omega, zeta), both with unit DC gain.
// Second-order states are (y, y' / omega).
void AppendSection(StateSpace* s, double omega, double zeta, bool second_order) {
  const Eigen::Index old_size = s->A.rows();
  const Eigen::Index size = old_size + (second_order ? 2 : 1);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(size, size);
  Eigen::VectorXd B = Eigen::VectorXd::Zero(size);
  A.topLeftCorner(old_size, old_size) = s->A;
  B.head(old_size) = s->B;
  const Eigen::Index y = old_size;
  // The section's input: the previous output, or u itself for the first section.
  auto drive = [&](Eigen::Index row, double gain) {
    if (old_size == 0) {
      B[row] = gain;
    } else {
      A(row, s->output) += gain;
    }
  };
  if (second_order) {
    // y' = omega v;  v' = -omega y - 2 zeta omega v + omega input.
    A(y, y + 1) = omega;
    A(y + 1, y) = -omega;
    A(y + 1, y + 1) = -2.0 * zeta * omega;
    drive(y + 1, omega);
  } else {
    // y' = -omega y + omega input.
    A(y, y) = -omega;
    drive(y, omega);
  }
  s->A = std::move(A);
  s->B = std::move(B);
  s->output = y;
}

StateSpace AxisModel(const MirrorDynamicsOptions& o) {
  StateSpace s{Eigen::MatrixXd(0, 0), Eigen::VectorXd(0), 0};
  const double wc = 2.0 * std::numbers::pi * o.lpf_cutoff_hz;
  // Butterworth: poles on the circle of radius wc at angles +-pi (n - 2k + 1) / (2 n),
  // k = 1..n/2, from the negative real axis (n = 2: 45 deg; n = 3: 60 deg and the real pole);
  // each conjugate pair is a section of damping cos(angle), an odd order adds the real pole.
  for (int k = 1; k <= o.lpf_order / 2; ++k) {
    const double angle = std::numbers::pi * (o.lpf_order - 2 * k + 1) / (2.0 * o.lpf_order);
    AppendSection(&s, wc, std::cos(angle), true);
  }
  if (o.lpf_order % 2 == 1) AppendSection(&s, wc, 1.0, false);
  AppendSection(&s, 2.0 * std::numbers::pi * o.resonance_hz, o.damping_ratio, true);
  return s;
}

}  // namespace

void MirrorDynamicsOptions::Check() const {
  const OptionChecks check("MirrorDynamicsOptions");
  check.Positive("resonance_hz", resonance_hz, "Hz");
  check.InRange("damping_ratio", damping_ratio, 0.0, 1.0, Interval::kOpen,
                "(an underdamped mirror)");
  check.InRange("lpf_order", lpf_order, 0, 8);
  if (lpf_order != 0) check.Positive("lpf_cutoff_hz", lpf_cutoff_hz, "Hz");
  check.Positive("waypoint_rate_hz", waypoint_rate_hz, "Hz");
  check.NonNegative("settle_s", settle_s, "s");
  check.Require(std::isfinite(sample_rate_hz) && sample_rate_hz >= waypoint_rate_hz,
                "sample_rate_hz",
                "a finite value >= waypoint_rate_hz (" + OptionValueText(waypoint_rate_hz) + " Hz)",
                sample_rate_hz);
  const double ratio = sample_rate_hz / waypoint_rate_hz;
  check.Require(std::abs(ratio - std::round(ratio)) <= 1e-9 * ratio && ratio <= 1e6,
                "sample_rate_hz", "a whole multiple (up to 1e6) of waypoint_rate_hz",
                sample_rate_hz);
}

int MirrorDynamicsOptions::SamplesPerWaypoint() const {
  return static_cast<int>(std::lround(sample_rate_hz / waypoint_rate_hz));
}

double LinesPerSecond(int waypoints_per_line, const MirrorDynamicsOptions& options) {
  options.Check();
  if (waypoints_per_line < 2) {
    throw Error("lines per second: a line needs at least 2 waypoints, got " +
                std::to_string(waypoints_per_line));
  }
  return 1.0 / (waypoints_per_line / options.waypoint_rate_hz + options.settle_s);
}

MirrorAxisDynamics::MirrorAxisDynamics(const MirrorDynamicsOptions& options, double step_s) {
  options.Check();
  if (!(std::isfinite(step_s) && step_s > 0.0)) {
    throw Error("mirror dynamics: the simulation step must be positive, got " +
                std::to_string(step_s) + " s");
  }
  const StateSpace s = AxisModel(options);
  const Eigen::Index n = s.A.rows();
  // Exact zero-order-hold discretisation from one matrix exponential (Pade with scaling and
  // squaring; omega * step is ~0.1 here, so it is accurate to rounding).
  Eigen::MatrixXd augmented = Eigen::MatrixXd::Zero(n + 1, n + 1);
  augmented.topLeftCorner(n, n) = s.A * step_s;
  augmented.topRightCorner(n, 1) = s.B * step_s;
  const Eigen::MatrixXd e = augmented.exp();
  Ad_ = e.topLeftCorner(n, n);
  Bd_ = e.topRightCorner(n, 1);
  // A is Hurwitz (all poles in the left half plane), hence invertible: x_eq = -A^-1 B u.
  equilibrium_ = s.A.partialPivLu().solve(-s.B);
  output_index_ = s.output;
  x_ = Eigen::VectorXd::Zero(n);
}

void MirrorAxisDynamics::Settle(double input) { x_ = equilibrium_ * input; }

double MirrorAxisDynamics::Advance(double input) {
  x_ = Ad_ * x_ + Bd_ * input;
  return output();
}

double DriveLagS(const MirrorDynamicsOptions& options) {
  options.Check();
  double lag = 2.0 * options.damping_ratio / (2.0 * std::numbers::pi * options.resonance_hz);
  if (options.lpf_order > 0) {
    const double wc = 2.0 * std::numbers::pi * options.lpf_cutoff_hz;
    // Poles p_k = wc exp(i t_k), t_k = pi/2 + pi (2k - 1) / (2n), k = 1..n (left half plane):
    // -Re(1 / p_k) = -cos(t_k) / wc = sin(pi (2k - 1) / (2n)) / wc; n = 2 gives sqrt(2) / wc.
    for (int k = 1; k <= options.lpf_order; ++k) {
      lag += std::sin(std::numbers::pi * (2 * k - 1) / (2.0 * options.lpf_order)) / wc;
    }
  }
  return lag;
}

TiltPath SimulateLine(const MemsLaser& laser, std::span<const Eigen::Vector2d> waypoint_volts,
                      const MirrorDynamicsOptions& options, bool dynamics) {
  options.Check();
  const std::size_t m = waypoint_volts.size();
  if (m < 2) {
    throw Error("simulate line: a line needs at least 2 waypoints, got " + std::to_string(m));
  }
  std::vector<Eigen::Vector2d> tilts;
  tilts.reserve(m);
  for (std::size_t j = 0; j < m; ++j) {
    if (!waypoint_volts[j].allFinite()) {
      throw Error("simulate line: waypoint " + std::to_string(j) + " is not finite");
    }
    tilts.push_back(laser.TiltFromVolts(waypoint_volts[j]));
  }
  const int per_waypoint = options.SamplesPerWaypoint();
  const double step_s = 1.0 / options.sample_rate_hz;
  const std::size_t count = (m - 1) * static_cast<std::size_t>(per_waypoint) + 1;
  TiltPath path;
  path.samples.resize(count);
  for (std::size_t i = 0; i < count; ++i) path.samples[i].time_s = static_cast<double>(i) * step_s;

  if (!dynamics) {
    for (std::size_t i = 0; i < count; ++i) {
      const std::size_t j = std::min(i / per_waypoint, m - 2);
      // Integer arithmetic for the phase, so that waypoint instants give fraction exactly 0
      // (or 1 for the last waypoint) and the path passes through the waypoints exactly.
      const std::size_t into = i - j * per_waypoint;
      if (into == 0) {
        path.samples[i].tilt_rad = tilts[j];
      } else if (into == static_cast<std::size_t>(per_waypoint)) {
        path.samples[i].tilt_rad = tilts[j + 1];
      } else {
        const double fraction = static_cast<double>(into) / per_waypoint;
        path.samples[i].tilt_rad = tilts[j] + fraction * (tilts[j + 1] - tilts[j]);
      }
    }
    return path;
  }

  MirrorAxisDynamics axis_x(options, step_s), axis_y(options, step_s);
  axis_x.Settle(tilts[0].x());
  axis_y.Settle(tilts[0].y());
  // The exposure opens `lag` samples after the DAC starts the line (see DriveLagS).
  const std::size_t lag = static_cast<std::size_t>(std::lround(DriveLagS(options) / step_s));
  Eigen::Vector2d tilt(axis_x.output(), axis_y.output());
  if (lag == 0) path.samples[0].tilt_rad = tilt;
  for (std::size_t i = 1; i < count + lag; ++i) {
    // The step from sample i - 1 to i lies in period j = (i - 1) / per_waypoint, during which
    // the DAC holds waypoint j + 1; after the last waypoint it holds that one.
    const Eigen::Vector2d& command = tilts[std::min((i - 1) / per_waypoint + 1, m - 1)];
    tilt = Eigen::Vector2d(axis_x.Advance(command.x()), axis_y.Advance(command.y()));
    if (i >= lag) path.samples[i - lag].tilt_rad = tilt;
  }
  return path;
}

}  // namespace uwscan::scanner
