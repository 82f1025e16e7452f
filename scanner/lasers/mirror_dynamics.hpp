#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "scanner/lasers/mems_laser.hpp"

namespace uwscan::scanner {

// Dynamics of the MEMS mirror and its drive, seed 001 Sec. II-C: each axis is a lightly damped
// second-order system (resonance 1.3 kHz, damping ratio 6.5e-3), driven through a low-pass
// filter that keeps the DAC's steps from ringing it up.
//
// The model is Hammerstein: the static nonlinearity of MemsLaser turns each held DAC command
// into its "static-equivalent tilt" (the tilt it would give once settled), and that signal
// goes through the linear LPF and plant, both with unit DC gain. The seed does not say where
// the nonlinearity sits; putting it first keeps every settled tilt equal to the static one.
//
// Timeline of one line (m waypoints, T = 1 / waypoint_rate_hz, t = 0 when the exposure
// opens): the DAC issues waypoint 0 at t = -(T + settle_s) and the mirror is taken as settled
// on it by t = 0; it then issues waypoint j + 1 at t = j T, so that ideally the mirror reaches
// waypoint j + 1 at t = (j + 1) T; the exposure closes at t = (m - 1) T, when the next line's
// waypoint 0 is issued. The line period is thus m T + settle_s.
//
// With the dynamics on, the filtered mirror trails its commands by the drive's lag (DriveLagS:
// the low-frequency group delay of the LPF and the plant, 1.5 ms for the default 150 Hz
// filter, i.e. five waypoint periods at 3500 Hz). The camera trigger is synchronised with the
// mirror, not with the DAC: the exposure opens and closes that lag later, while the DAC holds
// the last waypoint. Lines still follow each other every m T + settle_s (the next line's
// commands start while the exposure of this one ends), so the lag costs no speed.
struct MirrorDynamicsOptions {
  double resonance_hz = 1300.0;      // undamped natural frequency of each axis, Hz
  double damping_ratio = 6.5e-3;     // zeta, unitless
  double lpf_cutoff_hz = 150.0;      // -3 dB frequency of the drive filter, Hz
  int lpf_order = 2;                 // Butterworth order, 0 (no filter) .. 8
  double waypoint_rate_hz = 3500.0;  // DAC update rate, Hz
  double settle_s = 0.5e-3;          // dwell at a line's first waypoint before the exposure, s
  double sample_rate_hz = 70000.0;   // simulated samples per second; a whole multiple of the
                                     // waypoint rate so that every waypoint instant is a sample

  // Throws uwscan::Error naming the field when a value is unusable.
  void Check() const;
  // Samples per waypoint period (sample_rate_hz / waypoint_rate_hz).
  int SamplesPerWaypoint() const;
};

// Low-frequency group delay of the drive, seconds: how long the mirror trails a slow ramp of
// commands. Butterworth poles p_k give sum_k -Re(1 / p_k); the plant adds 2 zeta / omega0.
double DriveLagS(const MirrorDynamicsOptions& options);

// Lines per second when every line has `waypoints_per_line` waypoints: 1 / (m T + settle_s).
double LinesPerSecond(int waypoints_per_line, const MirrorDynamicsOptions& options);

// One axis, LPF then plant, as a continuous state-space model discretised exactly for a
// zero-order-held input over a fixed step: [Ad Bd; 0 1] = exp([A B; 0 0] step_s). Second-order
// sections use the states (y, y' / omega), which keeps the matrix balanced although omega is
// ~1e4 rad/s.
class MirrorAxisDynamics {
 public:
  // Throws uwscan::Error if the options fail Check() or step_s is not positive.
  MirrorAxisDynamics(const MirrorDynamicsOptions& options, double step_s);

  // Puts every state at the equilibrium of a constant input (the axis at rest there).
  void Settle(double input);
  // Holds `input` over one step; returns the output (tilt) at the end of it.
  double Advance(double input);
  double output() const { return x_[output_index_]; }
  int state_size() const { return static_cast<int>(x_.size()); }

 private:
  Eigen::MatrixXd Ad_;
  Eigen::VectorXd Bd_;
  Eigen::VectorXd equilibrium_;  // states for a unit constant input
  Eigen::VectorXd x_;
  Eigen::Index output_index_ = 0;
};

struct TiltSample {
  double time_s = 0.0;  // from the opening of the exposure
  Eigen::Vector2d tilt_rad = Eigen::Vector2d::Zero();
};

// The mirror's tilt over one line's exposure, sampled at options.sample_rate_hz from t = 0 to
// (m - 1) T inclusive ((m - 1) * SamplesPerWaypoint() + 1 samples).
struct TiltPath {
  std::vector<TiltSample> samples;
};

// dynamics = false: the ideal path, straight in tilt space from each waypoint's tilt to the
// next over one period (seed: the mirror follows the shortest path between waypoints in angle
// space); it passes through every waypoint exactly, at t = j T.
// dynamics = true: the held commands through LPF and plant per axis, from rest at waypoint 0.
// Throws uwscan::Error with fewer than 2 waypoints or a non-finite one.
TiltPath SimulateLine(const MemsLaser& laser, std::span<const Eigen::Vector2d> waypoint_volts,
                      const MirrorDynamicsOptions& options, bool dynamics);

}  // namespace uwscan::scanner
