// The dives' peak noise (exact peaks perturbed along the detection axis) stands for the
// detector's error on their stripes: rendered with the accuracy experiments' image stages and
// detected, each dive's stripes must err by what its scene says.
#include "scanner/sim/effects.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "scanner/sim/scene.hpp"
#include "scanner/sim/simulator.hpp"

namespace uwscan::scanner::sim {
namespace {

class DivePeakNoise : public ::testing::TestWithParam<const char*> {};

TEST_P(DivePeakNoise, IsTheDetectorsErrorOnTheDivesRenderedStripes) {
  Scene scene = LoadScene(std::string(UWSCAN_SOURCE_DIR_FOR_TESTS) + "/data/scenes/" + GetParam());
  ASSERT_TRUE(scene.effects.peak_noise.on);
  const double modelled_px = scene.effects.peak_noise.sigma_px;
  scene.effects = RealisticImageEffects(true, scene.effects);
  const Simulator simulator(scene);
  // Frames spread over the first sweeps: stripes on the seabed, pipes and clutter.
  const std::int64_t frames = std::min<std::int64_t>(simulator.frame_count(), 400);
  std::vector<double> errors;
  for (std::int64_t i = 0; i < frames; i += 7) {
    const std::vector<double> e = PeakErrorsPx(simulator.Frame(i), scene.detector.axis);
    errors.insert(errors.end(), e.begin(), e.end());
  }
  ASSERT_GT(errors.size(), 2000u);
  const double n = static_cast<double>(errors.size());
  double mean = 0.0;
  for (const double e : errors) mean += e / n;
  double variance = 0.0;
  for (const double e : errors) variance += (e - mean) * (e - mean) / n;
  const double measured_px = std::sqrt(variance);
  // The same from the median absolute deviation: a few peaks matched to the wrong crossing
  // (up to 3 px away) cannot carry it.
  std::vector<double> deviations;
  for (const double e : errors) deviations.push_back(std::abs(e - mean));
  std::nth_element(deviations.begin(),
                   deviations.begin() + static_cast<std::ptrdiff_t>(deviations.size() / 2),
                   deviations.end());
  const double robust_px = 1.4826 * deviations[deviations.size() / 2];
  std::printf(
      "%s: detector error std %.3f px (from the MAD %.3f px) over %zu peaks, the scene's peak "
      "noise %.3f px\n",
      GetParam(), measured_px, robust_px, errors.size(), modelled_px);
  EXPECT_NEAR(measured_px / modelled_px, 1.0, 0.2) << measured_px << " px measured";
  EXPECT_NEAR(robust_px / modelled_px, 1.0, 0.2) << robust_px << " px measured (MAD)";
}

INSTANTIATE_TEST_SUITE_P(Dives, DivePeakNoise,
                         ::testing::Values("inspection_short.yaml", "inspection_loop.yaml",
                                           "inspection_pipe.yaml", "inspection_long.yaml",
                                           "inspection_mems.yaml", "inspection_loop_mems.yaml"));

}  // namespace
}  // namespace uwscan::scanner::sim
