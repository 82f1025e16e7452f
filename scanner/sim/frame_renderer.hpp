#pragma once

#include <cstdint>
#include <vector>

#include "scanner/sim/effects.hpp"
#include "scanner/sim/stripe_tracer.hpp"
#include "scanner/stripe/stripe_render.hpp"

namespace uwscan::scanner::sim {

// A point of the laser beam in the water as the camera sees it: backscattered light.
struct GlowSample {
  Eigen::Vector2d px;
  double level = 0.0;  // image units before blur
};

struct FrameRenderInput {
  int width_px = 0;
  int height_px = 0;
  double focal_px = 1.0;  // to turn the beam's footprint (metres) into pixels
  StripeAxis axis = StripeAxis::kRows;
  std::vector<TracedPeak> peaks;  // exact stripe crossings of the frame
  std::vector<GlowSample> glow;   // backscatter samples (empty when backscatter is off)
  double attenuation_per_m = 0.0;
};

// Renders one camera frame from the exact stripe of a frame through the image stages of
// `effects` that are on: stripe profile (blur, beam footprint), reflectance, incidence and
// range falloff, attenuation, speckle, backscatter glow, ambient light, shot and read noise,
// quantisation and saturation. The stripe's cross-section is the Gaussian of RenderStripes
// integrated over each pixel. Deterministic for a given seed. StripeFrame::truth_px holds the
// exact centre of the first peak of each line (NaN where there is none).
StripeFrame RenderFrame(const FrameRenderInput& input, const SimulationEffects& effects,
                        std::uint64_t seed);

}  // namespace uwscan::scanner::sim
