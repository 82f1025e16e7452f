#include "scanner/sim/simulator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/imr_objects.hpp"
#include "scanner/triangulation/triangulator_factory.hpp"

namespace uwscan::scanner::sim {
namespace {

Eigen::Isometry3d At(double x, double y, double z) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

// The default galvanometer scanner looking at a plane at 1.1 m, a sphere and a box in front of
// it; every 10th mirror step.
Scene GalvoScene() {
  Scene scene;
  scene.source = "test scene";
  scene.scanner.file = "data/scanners/galvo_default.yaml";
  scene.scanner.model =
      LoadScanner(std::string(UWSCAN_SOURCE_DIR_FOR_TESTS) + "/data/scanners/galvo_default.yaml");
  scene.scanner.galvo.step_stride = 10;
  scene.trajectory.poses.push_back({0.0, Eigen::Isometry3d::Identity()});
  scene.detector.axis = StripeAxis::kRows;
  SceneObject wall;
  wall.name = "wall";
  wall.shape = ObjectShape::kPlane;
  wall.mesh = MakeRectangle(3.0, 3.0);
  wall.T_W_O = At(0.0, 0.0, 1.1);
  wall.reflectance = 0.5;
  SceneObject ball;
  ball.name = "ball";
  ball.shape = ObjectShape::kSphere;
  ball.sphere_radius_m = 0.1;
  ball.T_W_O = At(0.05, -0.1, 0.8);
  ball.reflectance = 0.7;
  SceneObject box;
  box.name = "box";
  box.shape = ObjectShape::kBox;
  box.mesh = MakeBox(Eigen::Vector3d(0.1, 0.1, 0.1));
  box.T_W_O = At(-0.1, 0.15, 0.9);
  box.reflectance = 0.4;
  scene.objects = {wall, ball, box};
  return scene;
}

struct Recovery {
  double max_error_m = 0.0;
  std::int64_t points = 0;
  std::int64_t peaks = 0;
};

Recovery Reconstruct(const Simulator& simulator, TriangulationMethod method) {
  const std::unique_ptr<Triangulator> triangulator =
      MakeTriangulator(simulator.scanner(), simulator.scan_pattern(), method);
  Recovery r;
  for (std::int64_t i = 0; i < simulator.frame_count(); ++i) {
    const SimulatedFrame frame = simulator.Frame(i);
    std::vector<TriangulatedPoint> out(frame.peaks_px.size());
    triangulator->TriangulateFrame(frame.command, frame.peaks_px, out);
    r.peaks += static_cast<std::int64_t>(out.size());
    for (size_t k = 0; k < out.size(); ++k) {
      if (!out[k].ok()) continue;
      const Eigen::Vector3d p_W = frame.T_W_C * out[k].p_C;
      r.max_error_m = std::max(r.max_error_m, (p_W - frame.truth_W[k]).norm());
      ++r.points;
    }
  }
  return r;
}

TEST(Simulator, NoiseFreeDiveRecoversGroundTruthWithTheExactMethod) {
  const Simulator simulator(GalvoScene());
  const Recovery r = Reconstruct(simulator, TriangulationMethod::kRayRay);
  EXPECT_GT(r.points, 5000);
  EXPECT_GE(r.points, r.peaks * 99 / 100);  // near-parallel rays may be refused, nothing else
  EXPECT_LE(r.max_error_m, 1e-6);
}

TEST(Simulator, NoiseFreeRecoveryHoldsWithoutRefractionOrDistortionAndOnAMovedVehicle) {
  Scene scene = GalvoScene();
  scene.effects.refraction = false;
  scene.effects.lens_distortion = false;
  scene.trajectory.poses[0].T_W_V = At(10.0, -5.0, 2.0);
  scene.trajectory.poses[0].T_W_V.linear() =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (SceneObject& o : scene.objects) o.T_W_O = scene.trajectory.poses[0].T_W_V * o.T_W_O;
  const Simulator simulator(scene);
  const Recovery r = Reconstruct(simulator, TriangulationMethod::kRayRay);
  EXPECT_GT(r.points, 5000);
  EXPECT_LE(r.max_error_m, 1e-6);
}

TEST(Simulator, RayConeIsCloseAndRayPlaneIsNotUnderWater) {
  const Simulator simulator(GalvoScene());
  EXPECT_LE(Reconstruct(simulator, TriangulationMethod::kRayCone).max_error_m, 2e-4);
  EXPECT_GT(Reconstruct(simulator, TriangulationMethod::kRayPlane).max_error_m, 1e-3);
}

TEST(Simulator, RefractionAndDistortionStagesMoveTheStripe) {
  const Simulator base(GalvoScene());
  for (int stage = 0; stage < 2; ++stage) {
    Scene scene = GalvoScene();
    (stage == 0 ? scene.effects.refraction : scene.effects.lens_distortion) = false;
    const Simulator changed(scene);
    const SimulatedFrame a = base.Frame(10);
    const SimulatedFrame b = changed.Frame(10);
    // The largest shift of the stripe along a row both frames share.
    double largest_shift = 0.0;
    for (const Eigen::Vector2d& pa : a.peaks_px) {
      for (const Eigen::Vector2d& pb : b.peaks_px) {
        if (pa.y() == pb.y()) largest_shift = std::max(largest_shift, std::abs(pa.x() - pb.x()));
      }
    }
    EXPECT_GT(largest_shift, 1.0) << "stage " << stage;
  }
}

TEST(Simulator, OcclusionRemovesSpotsTheCameraCannotSee) {
  Scene scene = GalvoScene();
  const Simulator with(scene);
  scene.effects.occlusion = false;
  const Simulator without(scene);
  std::int64_t seen = 0, all = 0;
  for (std::int64_t i = 0; i < with.frame_count(); ++i) {
    const SimulatedFrame a = with.Frame(i);
    const SimulatedFrame b = without.Frame(i);
    seen += static_cast<std::int64_t>(a.peaks_px.size());
    all += static_cast<std::int64_t>(b.peaks_px.size());
    // Every visible spot is among the spots traced without occlusion (solved to 1e-9 px).
    for (const Eigen::Vector2d& p : a.peaks_px) {
      const bool found =
          std::any_of(b.peaks_px.begin(), b.peaks_px.end(), [&](const Eigen::Vector2d& q) {
            return q.y() == p.y() && std::abs(q.x() - p.x()) < 1e-6;
          });
      EXPECT_TRUE(found) << p.transpose();
    }
  }
  EXPECT_LT(seen, all);  // the sphere and the box shadow part of the wall from the camera
}

TEST(Simulator, FramesAreDeterministicAndIndependentOfOrder) {
  Scene scene = GalvoScene();
  scene.effects.image.on = true;
  scene.effects.sensor_noise.on = true;
  scene.effects.speckle.on = true;
  const Simulator a(scene);
  const Simulator b(scene);
  const SimulatedFrame late_first = b.Frame(12);
  const SimulatedFrame f = a.Frame(12);
  ASSERT_TRUE(f.image && late_first.image);
  EXPECT_EQ(f.image->mono8, late_first.image->mono8);
  EXPECT_EQ(f.peaks_px, late_first.peaks_px);
  scene.seed = 2;
  const Simulator c(scene);
  EXPECT_NE(c.Frame(12).image->mono8, f.image->mono8);
}

TEST(Simulator, CleanRenderedStripesAreDetectedAtTheExactCrossings) {
  Scene scene = GalvoScene();
  scene.effects.image.on = true;
  scene.effects.image.blur_sigma_px = 1.5;
  const Simulator simulator(scene);
  int matched = 0;
  double sum2 = 0.0;
  for (std::int64_t i = 0; i < simulator.frame_count(); ++i) {
    const SimulatedFrame frame = simulator.Frame(i);
    ASSERT_TRUE(frame.image);
    for (size_t k = 0; k < frame.peaks_px.size(); ++k) {
      const double exact = frame.image->truth_px[static_cast<size_t>(frame.peaks_px[k].y())];
      if (frame.object_ids[k] < 0 || std::isnan(exact)) continue;
      sum2 += (frame.peaks_px[k].x() - exact) * (frame.peaks_px[k].x() - exact);
      ++matched;
    }
  }
  ASSERT_GT(matched, 3000);
  // Quantised 8-bit stripes of varying height: the detector's clean-stripe accuracy.
  EXPECT_LT(std::sqrt(sum2 / matched), 0.05);
  const Recovery r = Reconstruct(simulator, TriangulationMethod::kRayRay);
  EXPECT_LT(r.max_error_m, 2e-3);
}

// Peak noise moves each exact peak along the detection axis only, by the scene's sigma; the
// frame keeps the exact crossing beside it.
TEST(Simulator, PeakNoiseIsGaussianAlongTheDetectionAxisAroundTheExactCrossing) {
  Scene scene = GalvoScene();
  scene.effects.peak_noise.on = true;
  scene.effects.peak_noise.sigma_px = 0.2;
  const Simulator simulator(scene);
  std::vector<double> errors;
  for (std::int64_t i = 0; i < simulator.frame_count(); ++i) {
    const SimulatedFrame frame = simulator.Frame(i);
    ASSERT_EQ(frame.crossing_px.size(), frame.peaks_px.size());
    for (std::size_t k = 0; k < frame.peaks_px.size(); ++k) {
      EXPECT_EQ(frame.peaks_px[k].y(), frame.crossing_px[k].y());  // the same image row
    }
    const std::vector<double> e = PeakErrorsPx(frame, StripeAxis::kRows);
    errors.insert(errors.end(), e.begin(), e.end());
  }
  ASSERT_GT(errors.size(), 5000u);
  double sum = 0.0, sum2 = 0.0;
  for (const double e : errors) {
    sum += e;
    sum2 += e * e;
  }
  const double n = static_cast<double>(errors.size());
  EXPECT_NEAR(sum / n, 0.0, 4.0 * 0.2 / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.2, 0.01);
  // Gaussian: 68.3 % within one sigma, 95.4 % within two.
  const auto within = [&](double k) {
    return static_cast<double>(std::count_if(errors.begin(), errors.end(),
                                             [&](double e) { return std::abs(e) <= k * 0.2; })) /
           n;
  };
  EXPECT_NEAR(within(1.0), 0.683, 0.02);
  EXPECT_NEAR(within(2.0), 0.954, 0.01);

  scene.effects.peak_noise.on = false;
  const SimulatedFrame exact = Simulator(scene).Frame(simulator.frame_count() / 2);
  ASSERT_FALSE(exact.peaks_px.empty());
  for (std::size_t k = 0; k < exact.peaks_px.size(); ++k)
    EXPECT_EQ(exact.peaks_px[k], exact.crossing_px[k]);
}

// Noise that moves a crossing near the sensor's edge off it drops that peak, as no detector
// reports a peak off the sensor (the camera's profile encoding refuses one); the frame's arrays
// stay one entry per peak.
TEST(Simulator, PeakNoiseNeverPutsAPeakOffTheSensor) {
  Scene scene = GalvoScene();
  scene.effects.peak_noise.on = true;
  scene.effects.peak_noise.sigma_px = 400.0;
  const Simulator noisy(scene);
  scene.effects.peak_noise.on = false;
  const Simulator exact(scene);
  const double width_px = noisy.scanner().camera().camera.width_px;
  std::size_t kept = 0, crossings = 0;
  for (std::int64_t i = 0; i < noisy.frame_count(); i += 7) {
    const SimulatedFrame frame = noisy.Frame(i);
    ASSERT_EQ(frame.crossing_px.size(), frame.peaks_px.size());
    ASSERT_EQ(frame.truth_W.size(), frame.peaks_px.size());
    for (const Eigen::Vector2d& px : frame.peaks_px) {
      EXPECT_GE(px.x(), -0.5);
      EXPECT_LE(px.x(), width_px - 0.5);
    }
    kept += frame.peaks_px.size();
    crossings += exact.Frame(i).peaks_px.size();
  }
  EXPECT_GT(kept, crossings / 4);
  EXPECT_LT(kept, crossings);
}

TEST(Simulator, EffectsThatAreOffChangeNothingWhateverTheirParameters) {
  Scene base = GalvoScene();
  base.effects.image.on = true;
  Scene tweaked = base;
  tweaked.effects.beam.diameter_m = 0.01;
  tweaked.effects.sensor_noise.read_sigma = 9.0;
  tweaked.effects.speckle.contrast = 0.9;
  tweaked.effects.backscatter.level = 99.0;
  tweaked.effects.ambient.level = 50.0;
  tweaked.effects.navigation_drift.position_walk_m_per_sqrt_s = 1.0;
  tweaked.water.attenuation_per_m = 3.0;
  const Simulator a(base);
  const Simulator b(tweaked);
  for (std::int64_t i : {3, 10, 17}) {
    const SimulatedFrame fa = a.Frame(i);
    const SimulatedFrame fb = b.Frame(i);
    EXPECT_EQ(fa.image->mono8, fb.image->mono8);
    EXPECT_EQ(fa.peaks_px, fb.peaks_px);
  }
  const std::vector<NavigationSample> na = a.Navigation(20.0);
  const std::vector<NavigationSample> nb = b.Navigation(20.0);
  ASSERT_EQ(na.size(), nb.size());
  for (size_t k = 0; k < na.size(); ++k) EXPECT_TRUE(na[k].T_W_V.isApprox(nb[k].T_W_V, 0.0));
}

TEST(Simulator, EveryImageStageChangesTheFrameWhenOn) {
  Scene base = GalvoScene();
  base.effects.image.on = true;
  base.water.attenuation_per_m = 0.5;
  const std::vector<std::uint8_t> reference = Simulator(base).Frame(10).image->mono8;
  for (int stage = 0; stage < 6; ++stage) {
    Scene scene = base;
    switch (stage) {
      case 0:
        scene.effects.beam.on = true;
        break;
      case 1:
        scene.effects.sensor_noise.on = true;
        break;
      case 2:
        scene.effects.speckle.on = true;
        break;
      case 3:
        scene.effects.attenuation = true;
        break;
      case 4:
        scene.effects.backscatter.on = true;
        break;
      case 5:
        scene.effects.ambient.on = true;
        break;
    }
    const SimulatedFrame frame = Simulator(scene).Frame(10);
    ASSERT_TRUE(frame.image);
    EXPECT_NE(frame.image->mono8, reference) << "stage " << stage;
    EXPECT_FALSE(frame.peaks_px.empty()) << "stage " << stage;
  }
}

TEST(Simulator, MotionStageMovesTheScannerDuringASweep) {
  Scene scene = GalvoScene();
  scene.trajectory.poses = {{0.0, At(0, 0, 0)}, {1.0, At(0.5, 0, 0)}};
  const Simulator still(scene);
  scene.effects.motion = true;
  const Simulator moving(scene);
  const SimulatedFrame first = still.Frame(0), last = still.Frame(still.frame_count() - 1);
  EXPECT_TRUE(first.T_W_C.isApprox(last.T_W_C, 0.0));
  const SimulatedFrame m_first = moving.Frame(0), m_last = moving.Frame(moving.frame_count() - 1);
  const double expected = 0.5 * (m_last.time_s - m_first.time_s);
  EXPECT_NEAR((m_last.T_W_C.translation() - m_first.T_W_C.translation()).norm(), expected, 1e-12);
}

TEST(Simulator, NavigationDriftIsASeededRandomWalkAwayFromTheTruth) {
  Scene scene = GalvoScene();
  scene.scanner.sweeps = 20;
  scene.effects.navigation_drift.on = true;
  const std::vector<NavigationSample> a = Simulator(scene).Navigation(20.0);
  const std::vector<NavigationSample> b = Simulator(scene).Navigation(20.0);
  ASSERT_GT(a.size(), 10u);
  EXPECT_TRUE(a.front().T_W_V.isApprox(Eigen::Isometry3d::Identity(), 0.0));  // starts true
  double drift = 0.0;
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_TRUE(a[k].T_W_V.isApprox(b[k].T_W_V, 0.0));
    drift = std::max(drift, a[k].T_W_V.translation().norm());
  }
  EXPECT_GT(drift, 0.0);
}

TEST(Simulator, NoRowCarriesTheSameSpotTwice) {
  // The sphere's rim is seen at grazing angles, where the stripe's image jumps between samples.
  const Simulator simulator(GalvoScene());
  for (std::int64_t i = 0; i < simulator.frame_count(); ++i) {
    const SimulatedFrame frame = simulator.Frame(i);
    for (size_t k = 1; k < frame.peaks_px.size(); ++k) {
      const Eigen::Vector2d& p = frame.peaks_px[k - 1];
      const Eigen::Vector2d& q = frame.peaks_px[k];
      EXPECT_FALSE(p.y() == q.y() && std::abs(p.x() - q.x()) < 1e-3)
          << "frame " << i << " row " << q.y();
    }
  }
}

TEST(Simulator, WithoutMotionTheNavigationHoldsThePoseOfEachSweep) {
  Scene scene = GalvoScene();
  scene.scanner.sweeps = 3;
  scene.trajectory.poses = {{0.0, At(0, 0, 0)}, {1.0, At(0.5, 0, 0)}};
  const Simulator simulator(scene);
  const std::vector<NavigationSample> nav = simulator.Navigation(200.0);
  const double sweep_s = 21 * simulator.frame_period_s();
  ASSERT_GT(nav.back().time_s, 2.9 * sweep_s);  // the last sample brackets the last frame
  for (const NavigationSample& n : nav) {
    const int sweep = static_cast<int>(std::floor(n.time_s / sweep_s + 1e-9));
    if (sweep > 2) continue;  // the sample past the last frame
    const SimulatedFrame first = simulator.Frame(sweep * 21);
    EXPECT_TRUE(n.T_W_V.isApprox(first.T_W_C, 1e-12)) << n.time_s;
  }
}

TEST(Simulator, FrameOutOfRangeIsAnError) {
  const Simulator simulator(GalvoScene());
  EXPECT_THROW(simulator.Frame(-1), Error);
  EXPECT_THROW(simulator.Frame(simulator.frame_count()), Error);
}

// The default MEMS scanner looking at a plane 1.25 m away, a pattern of 12 lines.
Scene MemsScene(int waypoints_per_line) {
  Scene scene;
  scene.source = "test MEMS scene";
  scene.scanner.file = "data/scanners/mems_default.yaml";
  scene.scanner.model =
      LoadScanner(std::string(UWSCAN_SOURCE_DIR_FOR_TESTS) + "/data/scanners/mems_default.yaml");
  scene.scanner.mems.lines = 12;
  scene.scanner.mems.waypoints_per_line = waypoints_per_line;
  scene.trajectory.poses.push_back({0.0, Eigen::Isometry3d::Identity()});
  SceneObject wall;
  wall.name = "wall";
  wall.shape = ObjectShape::kPlane;
  wall.mesh = MakeRectangle(4.0, 4.0);
  wall.T_W_O = At(0.0, 0.0, 1.25);
  scene.objects = {wall};
  return scene;
}

TEST(SimulatorMems, LinesBecomePlanesInWaterToTheDesignsPrecision) {
  const Simulator simulator(MemsScene(50));
  EXPECT_EQ(simulator.frame_count(), 12);
  const Recovery r = Reconstruct(simulator, TriangulationMethod::kRayPlane);
  EXPECT_GT(r.points, 12 * 300);
  // Seed 001: the pre-curved lines are planes in water up to the pattern's planarity (tens of
  // micrometres here) and the fitted projection functions' error.
  EXPECT_LT(r.max_error_m, 3e-4);
  EXPECT_THROW(
      MakeTriangulator(simulator.scanner(), simulator.scan_pattern(), TriangulationMethod::kRayRay),
      Error);
}

TEST(SimulatorMems, MirrorDynamicsStageBendsTheLines) {
  Scene scene = MemsScene(10);
  const Simulator ideal(scene);
  scene.effects.mirror_dynamics = true;
  const Simulator dynamic(scene);
  const SimulatedFrame a = ideal.Frame(5);
  const SimulatedFrame b = dynamic.Frame(5);
  ASSERT_FALSE(a.peaks_px.empty());
  ASSERT_FALSE(b.peaks_px.empty());
  EXPECT_NE(a.peaks_px, b.peaks_px);
  // With few waypoints the filtered mirror cuts the corners of the pre-curved path: the
  // dynamic lines leave their planes farther than the ideal ones (seed 001, Fig. 5).
  const double ideal_error = Reconstruct(ideal, TriangulationMethod::kRayPlane).max_error_m;
  const double dynamic_error = Reconstruct(dynamic, TriangulationMethod::kRayPlane).max_error_m;
  EXPECT_LT(ideal_error, 1e-3);
  EXPECT_GT(dynamic_error, ideal_error);
  EXPECT_LT(dynamic_error, 2e-2);
  // Line timing comes from the drive: m / waypoint rate + settle.
  EXPECT_NEAR(dynamic.frame_period_s(), 10.0 / 3500.0 + 0.5e-3, 1e-12);
}

}  // namespace
}  // namespace uwscan::scanner::sim
