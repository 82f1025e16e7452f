#include "scanner/lasers/mirror_dynamics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <numbers>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/lasers/mems_scanner_model.hpp"

namespace uwscan::scanner {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Unit step response from rest, sampled every step_s for duration_s.
std::vector<double> StepResponse(const MirrorDynamicsOptions& options, double step_s,
                                 double duration_s) {
  MirrorAxisDynamics axis(options, step_s);
  axis.Settle(0.0);
  std::vector<double> y{axis.output()};
  const int steps = static_cast<int>(std::lround(duration_s / step_s));
  for (int i = 0; i < steps; ++i) y.push_back(axis.Advance(1.0));
  return y;
}

TEST(MirrorDynamics, PlantAloneIsTheAnalyticSecondOrderSystem) {
  MirrorDynamicsOptions options;
  options.lpf_order = 0;
  const double step_s = 1.0 / options.sample_rate_hz;
  const std::vector<double> y = StepResponse(options, step_s, 0.02);
  const double zeta = options.damping_ratio, wn = kTwoPi * options.resonance_hz;
  const double root = std::sqrt(1.0 - zeta * zeta), wd = wn * root;
  // The exact discretisation reproduces the continuous step response at every sample.
  double worst = 0.0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    const double t = i * step_s;
    const double exact =
        1.0 - std::exp(-zeta * wn * t) * (std::cos(wd * t) + zeta / root * std::sin(wd * t));
    worst = std::max(worst, std::abs(y[i] - exact));
  }
  EXPECT_LT(worst, 1e-10);

  // Overshoot exp(-pi zeta / sqrt(1 - zeta^2)) (98 %) at t = pi / wd; the samples straddle
  // the peak by at most half a step, which costs (wd step / 2)^2 / 2 of the amplitude.
  const auto peak = std::max_element(y.begin(), y.end());
  const double overshoot = *peak - 1.0;
  const double expected = std::exp(-std::numbers::pi * zeta / root);
  EXPECT_NEAR(overshoot, expected, 0.5 * std::pow(0.5 * wd * step_s, 2) * 2.0);
  EXPECT_NEAR((peak - y.begin()) * step_s, std::numbers::pi / wd, 0.5 * step_s);
  std::cout << "[ measured ] plant step: overshoot " << overshoot * 100 << " % (analytic "
            << expected * 100 << " %)\n";

  // Ringing frequency from the upward crossings of 1, interpolated, over 20 ms (26 periods).
  std::vector<double> crossings;
  for (std::size_t i = 1; i < y.size(); ++i) {
    if (y[i - 1] < 1.0 && y[i] >= 1.0) {
      crossings.push_back((i - 1 + (1.0 - y[i - 1]) / (y[i] - y[i - 1])) * step_s);
    }
  }
  ASSERT_GE(crossings.size(), 20u);
  const double period = (crossings.back() - crossings.front()) / (crossings.size() - 1);
  EXPECT_NEAR(1.0 / period, wd / kTwoPi, 1e-3 * wd / kTwoPi);
}

TEST(MirrorDynamics, LowPassFilterIsButterworth) {
  // With the plant far above the filter, the step shows the filter alone: a second-order
  // Butterworth (zeta = 1/sqrt 2) overshoots by exp(-pi) = 4.32 %.
  MirrorDynamicsOptions options;
  options.resonance_hz = 50000.0;
  options.damping_ratio = 0.9;
  options.sample_rate_hz = 3500.0 * 200;
  const std::vector<double> y = StepResponse(options, 1.0 / options.sample_rate_hz, 0.03);
  EXPECT_NEAR(*std::max_element(y.begin(), y.end()) - 1.0, std::exp(-std::numbers::pi), 1e-3);
  // Odd orders (a real pole) and high orders keep unit DC gain: the equilibrium of a unit
  // input has unit output and stays put.
  for (const int order : {1, 3, 8}) {
    options.lpf_order = order;
    MirrorAxisDynamics axis(options, 1.0 / options.sample_rate_hz);
    axis.Settle(1.0);
    EXPECT_NEAR(axis.output(), 1.0, 1e-15) << order;
    for (int i = 0; i < 1000; ++i) axis.Advance(1.0);
    EXPECT_NEAR(axis.output(), 1.0, 1e-12) << order;
  }
}

TEST(MirrorDynamics, DriveFilterTamesTheResonance) {
  const MirrorDynamicsOptions options;  // 150 Hz, 2nd-order Butterworth, ahead of the plant
  const double step_s = 1.0 / options.sample_rate_hz;
  const std::vector<double> y = StepResponse(options, step_s, 0.05);
  const double overshoot = *std::max_element(y.begin(), y.end()) - 1.0;
  // Residual ringing once the filter has settled (after 15 ms): the resonance sees the
  // filter's |H(j wn)| ~ (150 / 1300)^2.
  double ringing = 0.0;
  for (std::size_t i = static_cast<std::size_t>(0.015 / step_s); i < y.size(); ++i) {
    ringing = std::max(ringing, std::abs(y[i] - 1.0));
  }
  std::cout << "[ measured ] filtered step: overshoot " << overshoot * 100
            << " %, ringing after 15 ms " << ringing * 100 << " %\n";
  EXPECT_LT(overshoot, 0.06);  // Butterworth's own 4.3 % plus a little ringing
  EXPECT_LT(ringing, 0.01);
}

TEST(MirrorDynamics, IdealPathRunsStraightThroughEveryWaypoint) {
  const MemsScannerModel model = DefaultMemsScannerModel();
  const std::vector<Eigen::Vector2d> volts = {{0.0, -9.0}, {1e-9, -4.0}, {0.7, 1.5}, {-2.0, 9.9}};
  const TiltPath path = SimulateLine(model.laser, volts, model.dynamics, false);
  const int k = model.dynamics.SamplesPerWaypoint();
  ASSERT_EQ(path.samples.size(), 3u * k + 1);
  for (std::size_t j = 0; j < volts.size(); ++j) {
    const TiltSample& s = path.samples[j * k];
    EXPECT_EQ(s.tilt_rad, model.laser.TiltFromVolts(volts[j])) << j;  // exactly
    EXPECT_NEAR(s.time_s, j / model.dynamics.waypoint_rate_hz, 1e-15);
  }
  // Straight in tilt space in between: the midpoint of a segment is the mean of its ends.
  const Eigen::Vector2d a = model.laser.TiltFromVolts(volts[1]);
  const Eigen::Vector2d b = model.laser.TiltFromVolts(volts[2]);
  EXPECT_LT((path.samples[k + k / 2].tilt_rad - 0.5 * (a + b)).norm(), 1e-17);
}

TEST(MirrorDynamics, DynamicPathStartsSettledAndIsDeterministic) {
  const MemsScannerModel model = DefaultMemsScannerModel();
  std::vector<Eigen::Vector2d> volts;
  for (int j = 0; j < 50; ++j) volts.emplace_back(2.0 + 0.01 * j, -8.0 + 0.32 * j);
  const TiltPath a = SimulateLine(model.laser, volts, model.dynamics, true);
  const TiltPath b = SimulateLine(model.laser, volts, model.dynamics, true);
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (std::size_t i = 0; i < a.samples.size(); ++i) {
    ASSERT_EQ(a.samples[i].tilt_rad, b.samples[i].tilt_rad) << i;
  }
  // A line of one repeated waypoint keeps the mirror where it is.
  const std::vector<Eigen::Vector2d> still(5, Eigen::Vector2d(3.0, -1.0));
  for (const TiltSample& s : SimulateLine(model.laser, still, model.dynamics, true).samples) {
    EXPECT_LT((s.tilt_rad - model.laser.TiltFromVolts(still[0])).norm(), 1e-15);
  }
  // The exposure is shifted by the drive's lag, so the filtered mirror follows the ideal path
  // closely from the first sample to the last (it trails it only while the ramp starts up).
  const TiltPath ideal = SimulateLine(model.laser, volts, model.dynamics, false);
  ASSERT_EQ(ideal.samples.size(), a.samples.size());
  const double travel = (ideal.samples.back().tilt_rad - ideal.samples.front().tilt_rad).norm();
  double worst = 0.0;
  for (std::size_t i = 0; i < a.samples.size(); ++i) {
    worst = std::max(worst, (a.samples[i].tilt_rad - ideal.samples[i].tilt_rad).norm());
  }
  std::cout << "[ measured ] dynamic vs ideal path, lag-shifted exposure: worst "
            << worst / travel * 100 << " % of the line\n";
  EXPECT_LT(worst, 0.03 * travel);
  EXPECT_LT((a.samples.back().tilt_rad - ideal.samples.back().tilt_rad).norm(), 0.03 * travel);
}

TEST(MirrorDynamics, DriveLagIsTheLowFrequencyGroupDelay) {
  MirrorDynamicsOptions o;
  const double plant = 2.0 * o.damping_ratio / (2.0 * std::numbers::pi * o.resonance_hz);
  const double wc = 2.0 * std::numbers::pi * o.lpf_cutoff_hz;
  EXPECT_NEAR(DriveLagS(o), std::sqrt(2.0) / wc + plant, 1e-15);
  o.lpf_order = 1;
  EXPECT_NEAR(DriveLagS(o), 1.0 / wc + plant, 1e-15);
  o.lpf_order = 0;
  EXPECT_NEAR(DriveLagS(o), plant, 1e-18);
  // A slow ramp through the drive comes out delayed by exactly that lag.
  o.lpf_order = 3;
  const double step = 1.0 / o.sample_rate_hz;
  MirrorAxisDynamics axis(o, step);
  axis.Settle(0.0);
  const double slope = 0.01;  // rad/s
  double t = 0.0, out = 0.0;
  for (int i = 0; i < 20000; ++i) {
    t += step;
    out = axis.Advance(slope * (t - 0.5 * step));  // the held command: the ramp mid-step
  }
  EXPECT_NEAR((slope * t - out) / slope, DriveLagS(o), 1e-6);
}

TEST(MirrorDynamics, LinesPerSecondMatchesTheSeed) {
  const MirrorDynamicsOptions options;
  const double at_50 = LinesPerSecond(50, options);
  std::cout << "[ measured ] lines/s at 5, 20, 50, 100 waypoints: " << LinesPerSecond(5, options)
            << ", " << LinesPerSecond(20, options) << ", " << at_50 << ", "
            << LinesPerSecond(100, options) << "\n";
  EXPECT_NEAR(at_50, 1.0 / (50.0 / 3500.0 + 0.5e-3), 1e-9);
  EXPECT_NEAR(at_50, 70.0, 5.0);  // seed: ~70 lines/s, 140 k points/s
  EXPECT_GT(LinesPerSecond(20, options), at_50);
  EXPECT_THROW(LinesPerSecond(1, options), Error);
}

TEST(MirrorDynamics, OptionsAreChecked) {
  MirrorDynamicsOptions o;
  EXPECT_NO_THROW(o.Check());
  o.sample_rate_hz = 3500.0 * 20.5;  // waypoints would fall between samples
  EXPECT_THROW(o.Check(), Error);
  o = {};
  o.damping_ratio = 1.0;
  EXPECT_THROW(o.Check(), Error);
  o = {};
  o.lpf_order = 9;
  EXPECT_THROW(o.Check(), Error);
  o = {};
  o.settle_s = -1e-3;
  EXPECT_THROW(o.Check(), Error);
  EXPECT_THROW(MirrorAxisDynamics(MirrorDynamicsOptions{}, 0.0), Error);
  const MemsScannerModel model = DefaultMemsScannerModel();
  const std::vector<Eigen::Vector2d> one = {Eigen::Vector2d::Zero()};
  EXPECT_THROW(SimulateLine(model.laser, one, model.dynamics, false), Error);
}

}  // namespace
}  // namespace uwscan::scanner
