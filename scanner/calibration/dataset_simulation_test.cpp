#include "scanner/calibration/dataset_simulation.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <map>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "scanner/calibration/calibration_dataset.hpp"
#include "scanner/calibration/stripe_extraction.hpp"
#include "scanner/common/error.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"
#include "scanner/lasers/mems_scanner_model.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/imr_objects.hpp"
#include "scanner/sim/simulator.hpp"

namespace uwscan::scanner::calibration {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = UWSCAN_SOURCE_DIR_FOR_TESTS;

// This process's scratch folder, removed when the test program ends.
fs::path ScratchRoot() {
  return fs::temp_directory_path() / ("uwscan_dataset_simulation_test_" + std::to_string(getpid()));
}
struct RemoveScratch : ::testing::Environment {
  void TearDown() override { fs::remove_all(ScratchRoot()); }
};
[[maybe_unused]] const ::testing::Environment* const kRemoveScratch =
    ::testing::AddGlobalTestEnvironment(new RemoveScratch);

// A dataset folder that does not exist yet.
fs::path OutFolder(const std::string& name) {
  fs::path folder = ScratchRoot() / name;
  fs::remove_all(folder);
  return folder;
}

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

// A calibration scene at half image size; `head` holds water and effects, `calibration` the
// section's fields (indented by two spaces).
CalibrationScene Scene(const std::string& scanner, const std::string& head,
                       const std::string& calibration) {
  const std::string text = "uwscan_format: 1\nseed: 9\nscanner:\n  file: " +
                           (kSource / "data/scanners" / scanner).string() + "\n" + head +
                           "calibration:\n  image_scale: 0.5\n" + calibration;
  return ParseCalibrationScene(text, "test.yaml", kSource / "data/scenes");
}

RefractiveCamera TruthCamera(const DatasetTruth& truth) { return truth.scanner.camera(); }

// Pattern corners found in an image with OpenCV, in uwscan's pixel convention, by corner id.
std::map<int, Eigen::Vector2d> DetectCorners(const fs::path& image_file, const PatternSpec& spec,
                                             const DatasetTruth& truth,
                                             const Eigen::Isometry3d& T_C_O) {
  const cv::Mat image = cv::imread(image_file.string(), cv::IMREAD_GRAYSCALE);
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  if (spec.type == PatternType::kChessboard) {
    if (!cv::findChessboardCorners(image, cv::Size(spec.columns, spec.rows), corners)) return {};
    cv::cornerSubPix(image, corners, cv::Size(4, 4), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
    // The finder may start at either end of the board: take the order that fits the truth.
    const std::vector<Eigen::Vector3d> points = spec.CornerPoints_O();
    const std::optional<Eigen::Vector2d> first =
        TruthCamera(truth).ProjectPointInWater(T_C_O * points[0]);
    const bool reversed =
        first && (Eigen::Vector2d(corners.back().x, corners.back().y) - *first).norm() <
                     (Eigen::Vector2d(corners.front().x, corners.front().y) - *first).norm();
    for (size_t k = 0; k < corners.size(); ++k) {
      ids.push_back(static_cast<int>(reversed ? corners.size() - 1 - k : k));
    }
  } else {
    const cv::Ptr<cv::aruco::Dictionary> dictionary =
        cv::aruco::getPredefinedDictionary(ArucoDictionaryId(spec.dictionary));
    const cv::Ptr<cv::aruco::CharucoBoard> board =
        cv::aruco::CharucoBoard::create(spec.columns, spec.rows, static_cast<float>(spec.square_m),
                                        static_cast<float>(spec.marker_m), dictionary);
    std::vector<std::vector<cv::Point2f>> markers;
    std::vector<int> marker_ids;
    cv::aruco::detectMarkers(image, dictionary, markers, marker_ids);
    if (marker_ids.empty()) return {};
    cv::aruco::interpolateCornersCharuco(markers, marker_ids, image, board, corners, ids);
    // OpenCV 4.6 returns ChArUco corners 0.5 px right of and below where they are (see
    // target_renderer_test); its refinement window is set for full-size boards, so refine again.
    for (cv::Point2f& c : corners) c -= cv::Point2f(0.5f, 0.5f);
    if (!corners.empty()) {
      cv::cornerSubPix(
          image, corners, cv::Size(4, 4), cv::Size(-1, -1),
          cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
    }
  }
  std::map<int, Eigen::Vector2d> found;
  for (size_t k = 0; k < ids.size(); ++k)
    found[ids[k]] = Eigen::Vector2d(corners[k].x, corners[k].y);
  return found;
}

// Every pattern image shows the pattern where the truth says: detected corners against the
// exact projection of the board's corners at the true pose.
void CheckPatternImages(const CalibrationDataset& d, const DatasetTruth& truth) {
  const RefractiveCamera camera = TruthCamera(truth);
  std::vector<std::string> images = d.views;
  std::vector<Eigen::Isometry3d> poses = truth.T_C_O_views;
  for (const CalibrationDataset::Plane& plane : d.planes) images.push_back(plane.pattern_image);
  poses.insert(poses.end(), truth.T_C_O_planes.begin(), truth.T_C_O_planes.end());
  ASSERT_EQ(images.size(), poses.size());
  const std::vector<Eigen::Vector3d> points = d.pattern.CornerPoints_O();
  for (size_t i = 0; i < images.size(); ++i) {
    const std::map<int, Eigen::Vector2d> found =
        DetectCorners(d.ImagePath(images[i]), d.pattern, truth, poses[i]);
    EXPECT_GE(found.size(), points.size() * 3 / 4) << images[i];
    double sum = 0.0;
    for (const auto& [id, px] : found) {
      const std::optional<Eigen::Vector2d> exact =
          camera.ProjectPointInWater(poses[i] * points[static_cast<size_t>(id)]);
      ASSERT_TRUE(exact.has_value());
      sum += (px - *exact).squaredNorm();
    }
    const double rms = found.empty() ? 1e9 : std::sqrt(sum / static_cast<double>(found.size()));
    EXPECT_LT(rms, 0.15) << images[i];
    std::printf("[ %s %s ] %zu corners, RMS %.3f px to the truth\n", d.step.c_str(),
                images[i].c_str(), found.size(), rms);
  }
}

TEST(DatasetSimulation, IntrinsicsViewsInAirMatchTheirTruth) {
  const CalibrationScene scene =
      Scene("galvo_default.yaml", "water: {refractive_index: 1.0}\neffects: {refraction: false}\n",
            "  step: intrinsics\n"
            "  pattern: {type: chessboard, columns: 9, rows: 6, square_m: 0.03}\n"
            "  views: 4\n  distance_m: [0.5, 0.9]\n");
  const fs::path out = OutFolder("intrinsics");
  std::vector<double> progress;
  SimulateCalibrationDataset(scene, out, [&](double f) { progress.push_back(f); });
  const CalibrationDataset d = LoadCalibrationDataset(out);
  EXPECT_EQ(d.step, "intrinsics");
  EXPECT_EQ(d.width_px, 1024);
  EXPECT_EQ(d.height_px, 544);
  EXPECT_EQ(d.views.size(), 4u);
  EXPECT_FALSE(d.scanner_file.has_value());
  ASSERT_TRUE(d.truth_file.has_value());
  const DatasetTruth truth = LoadDatasetTruth(*d.truth_file);
  ASSERT_EQ(truth.T_C_O_views.size(), 4u);
  EXPECT_TRUE(truth.T_C_O_planes.empty());
  // In air, without the viewport: its glass takes the air's index.
  const GalvoScannerModel model = truth.scanner.galvo();
  EXPECT_EQ(model.camera.viewport.n_glass, 1.0);
  EXPECT_EQ(model.camera.camera.width_px, 1024);
  EXPECT_DOUBLE_EQ(model.camera.camera.fx_px, 875.0);
  EXPECT_DOUBLE_EQ(model.camera.camera.cx_px, 511.5);
  CheckPatternImages(d, truth);
  ASSERT_FALSE(progress.empty());
  EXPECT_DOUBLE_EQ(progress.back(), 1.0);
  EXPECT_TRUE(std::is_sorted(progress.begin(), progress.end()));
}

TEST(DatasetSimulation, ViewportCharucoUnderWaterWithItsInitialScanner) {
  const CalibrationScene scene =
      Scene("galvo_default.yaml", "water: {refractive_index: 1.33}\n",
            "  step: viewport\n"
            "  pattern: {type: charuco, columns: 8, rows: 6, square_m: 0.04, marker_m: 0.03}\n"
            "  initial_scanner: {file: ../scanners/galvo_cad.yaml, true_sections: [camera]}\n"
            "  views: 3\n  distance_m: [0.7, 1.1]\n");
  const fs::path out = OutFolder("viewport");
  SimulateCalibrationDataset(scene, out);
  const CalibrationDataset d = LoadCalibrationDataset(out);
  const DatasetTruth truth = LoadDatasetTruth(*d.truth_file);
  CheckPatternImages(d, truth);
  // The initial scanner: the true (scaled) camera, the CAD viewport.
  ASSERT_TRUE(d.scanner_file.has_value());
  EXPECT_EQ(d.scanner_file->filename(), "initial_scanner.yaml");
  const GalvoScannerModel initial = LoadScanner(*d.scanner_file).galvo();
  const GalvoScannerModel real = truth.scanner.galvo();
  EXPECT_EQ(initial.camera.camera.width_px, 1024);
  EXPECT_EQ(initial.camera.camera.fx_px, real.camera.camera.fx_px);
  EXPECT_EQ(initial.camera.camera.k1, real.camera.camera.k1);
  EXPECT_GT((initial.camera.viewport.normal - real.camera.viewport.normal).norm(), 0.01);
  EXPECT_NEAR(initial.camera.viewport.distance_m - real.camera.viewport.distance_m, 0.002, 1e-12);
}

// Stripe images against the exact stripe: the simulator without image stages, from the truth
// file alone (scanner and board pose), gives the exact peak of every row the stripe crosses.
void CheckStripes(const CalibrationScene& scene, const fs::path& out) {
  const CalibrationDataset d = LoadCalibrationDataset(out);
  const DatasetTruth truth = LoadDatasetTruth(*d.truth_file);
  CheckPatternImages(d, truth);
  ASSERT_EQ(d.planes.size(), truth.T_C_O_planes.size());
  const BoardGeometry board = BoardOf(scene.pattern, scene.board_size_m);
  for (size_t p = 0; p < d.planes.size(); ++p) {
    ASSERT_EQ(d.planes[p].stripes.size(), scene.mirror_steps.size());
    sim::Scene exact;
    exact.source = "exact";
    exact.water = scene.scene.water;
    exact.scanner.file = "truth.yaml";
    exact.scanner.model = truth.scanner;
    exact.scanner.galvo.step_min = -100;
    exact.scanner.galvo.step_max = 100;
    exact.trajectory.poses = {sim::TrajectoryPose{}};
    exact.effects.refraction = scene.scene.effects.refraction;
    exact.detector.axis = StripeAxis::kRows;
    sim::SceneObject object;
    object.shape = sim::ObjectShape::kPlane;
    object.mesh = sim::MakeRectangle(board.size_m.x(), board.size_m.y());
    object.T_W_O =
        truth.T_C_O_planes[p] * Eigen::Translation3d(board.centre_O.x(), board.centre_O.y(), 0.0);
    exact.objects = {object};
    const sim::Simulator simulator(exact);
    for (const auto& [image, step] : d.planes[p].stripes) {
      const StripeObservation found = ExtractStripe(d.ImagePath(image), step, scene.scene.detector);
      const sim::SimulatedFrame frame = simulator.Frame(step + 100);
      std::map<long, double> truth_u;
      for (const Eigen::Vector2d& px : frame.peaks_px) truth_u[std::lround(px.y())] = px.x();
      ASSERT_GT(truth_u.size(), 50u) << image;
      double sum = 0.0;
      int matched = 0;
      for (const Eigen::Vector2d& px : found.peaks_px) {
        const auto it = truth_u.find(std::lround(px.y()));
        if (it == truth_u.end()) continue;
        sum += (px.x() - it->second) * (px.x() - it->second);
        ++matched;
      }
      const double rms = std::sqrt(sum / std::max(matched, 1));
      EXPECT_GE(matched, static_cast<int>(truth_u.size()) * 9 / 10) << image;
      EXPECT_LE(found.peaks_px.size(), truth_u.size() + 2) << image;
      EXPECT_LT(rms, 0.15) << image;
      std::printf("[ %s %s ] %d of %zu rows, RMS %.3f px to the exact stripe\n", d.step.c_str(),
                  image.c_str(), matched, truth_u.size(), rms);
    }
  }
}

const char* kStripeEffects =
    "  image: {format: mono8, peak_level: 180, blur_sigma_px: 0.7}\n"
    "  beam: {diameter_m: 0.001, divergence_rad: 0.0011}\n"
    "  sensor_noise: {read_sigma: 1.0, electrons_per_level: 4}\n"
    "detector: {method: steger, axis: rows, threshold: 40}\n";

TEST(DatasetSimulation, LaserStripesInAirLieWhereTheTrueLaserFalls) {
  const CalibrationScene scene =
      Scene("galvo_default.yaml",
            std::string("water: {refractive_index: 1.0}\neffects:\n  refraction: false\n") +
                kStripeEffects,
            "  step: laser\n"
            "  pattern: {type: chessboard, columns: 9, rows: 6, square_m: 0.04}\n"
            "  board_size_m: [0.6, 0.45]\n"
            "  initial_scanner: ../scanners/galvo_cad.yaml\n"
            "  planes: 2\n  mirror_steps: [-50, 0, 50]\n  distance_m: [0.6, 0.9]\n");
  const fs::path out = OutFolder("laser");
  SimulateCalibrationDataset(scene, out);
  CheckStripes(scene, out);
  // Without true_sections the initial scanner is the CAD file, only its camera scaled.
  const GalvoScannerModel initial = LoadScanner(out / "initial_scanner.yaml").galvo();
  const GalvoScannerModel cad = LoadScanner(kSource / "data/scanners/galvo_cad.yaml").galvo();
  // A pose goes through its quaternion in the file: the same to the last bit or two.
  EXPECT_LT((initial.laser.T_C_L.matrix() - cad.laser.T_C_L.matrix()).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(initial.laser.mirror_step_rad, cad.laser.mirror_step_rad);
  EXPECT_EQ(initial.camera.camera.width_px, 1024);
}

TEST(DatasetSimulation, LaserViewportStripesUnderWaterLieWhereTheTrueLaserFalls) {
  const CalibrationScene scene =
      Scene("galvo_default.yaml",
            std::string("water: {refractive_index: 1.33, attenuation_per_m: 0.2}\neffects:\n"
                        "  attenuation: true\n") +
                kStripeEffects,
            "  step: laser_viewport\n"
            "  pattern: {type: chessboard, columns: 9, rows: 6, square_m: 0.04}\n"
            "  board_size_m: [0.6, 0.45]\n"
            "  planes: 2\n  mirror_steps: [-40, 40]\n  distance_m: [0.8, 1.1]\n");
  const fs::path out = OutFolder("laser_viewport");
  SimulateCalibrationDataset(scene, out);
  CheckStripes(scene, out);
}

TEST(DatasetSimulation, MemsDotsSitOnTheTrueBeam) {
  const CalibrationScene scene = Scene(
      "mems_default.yaml",
      "water: {refractive_index: 1.33}\neffects:\n  image: {format: mono16, peak_level: 40000}\n",
      "  step: mems\n"
      "  pattern: {type: charuco, columns: 10, rows: 7, square_m: 0.05, marker_m: 0.0375}\n"
      "  board_size_m: [0.8, 0.6]\n"
      "  initial_scanner: {file: ../scanners/mems_cad.yaml, true_sections: [camera, "
      "camera_viewport]}\n"
      "  planes: 2\n  volts_grid: [5, 4]\n  distance_m: [0.9, 1.3]\n");
  const fs::path out = OutFolder("mems");
  SimulateCalibrationDataset(scene, out);
  const CalibrationDataset d = LoadCalibrationDataset(out);
  const DatasetTruth truth = LoadDatasetTruth(*d.truth_file);
  CheckPatternImages(d, truth);
  const MemsScannerModel model = truth.scanner.mems();
  for (size_t p = 0; p < d.planes.size(); ++p) {
    EXPECT_GE(d.planes[p].dots.size(), 5u);
    EXPECT_LE(d.planes[p].dots.size(), 20u);
    const Eigen::Isometry3d& T_C_O = truth.T_C_O_planes[p];
    for (const auto& [image, volts] : d.planes[p].dots) {
      EXPECT_LE(volts.cwiseAbs().maxCoeff(), 9.0 + 1e-12);
      // Centroid of the dot (lights off, no noise: black is 0).
      const cv::Mat dot = cv::imread(d.ImagePath(image).string(), cv::IMREAD_UNCHANGED);
      ASSERT_EQ(dot.type(), CV_16UC1) << image;
      double sum = 0.0;
      Eigen::Vector2d moment = Eigen::Vector2d::Zero();
      for (int v = 0; v < dot.rows; ++v) {
        for (int u = 0; u < dot.cols; ++u) {
          const double value = dot.at<std::uint16_t>(v, u);
          sum += value;
          moment += value * Eigen::Vector2d(u, v);
        }
      }
      ASSERT_GT(sum, 0.0) << image;
      const RayTrace beam = model.laser.RayInWater(volts);
      ASSERT_TRUE(beam.ok());
      const Eigen::Vector3d normal = T_C_O.linear().col(2);
      const double t =
          normal.dot(T_C_O.translation() - beam.ray.origin) / normal.dot(beam.ray.direction);
      const std::optional<Eigen::Vector2d> exact = model.camera.ProjectPointInWater(beam.ray.At(t));
      ASSERT_TRUE(exact.has_value());
      EXPECT_LT((moment / sum - *exact).norm(), 0.02) << image;
    }
  }
  // The initial scanner reads as a MEMS scanner with the true camera and the CAD laser box.
  const MemsScannerModel initial = LoadScanner(*d.scanner_file).mems();
  EXPECT_EQ(initial.camera.camera.fx_px, model.camera.camera.fx_px);
  EXPECT_GT((initial.laser.emitter_origin_C - model.laser.emitter_origin_C).norm(), 1e-3);
}

TEST(DatasetSimulation, SameSceneSameDatasetAndNoOverwriting) {
  const CalibrationScene scene =
      Scene("galvo_default.yaml", "",
            "  step: viewport\n"
            "  pattern: {type: chessboard, columns: 7, rows: 5, square_m: 0.04}\n"
            "  views: 3\n  distance_m: [0.8, 1.2]\n  render: {noise_sigma: 3}\n");
  const fs::path a = OutFolder("same_a"), b = OutFolder("same_b");
  SimulateCalibrationDataset(scene, a);
  SimulateCalibrationDataset(scene, b);
  for (const char* file : {"manifest.yaml", "truth.yaml", "view_000.png", "view_002.png"}) {
    EXPECT_EQ(ReadFile(a / file), ReadFile(b / file)) << file;
  }
  try {
    SimulateCalibrationDataset(scene, a);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("exists and is not empty"), std::string::npos) << e.what();
  }
}

std::string SceneError(const std::string& text) {
  try {
    ParseCalibrationScene(text, "test.yaml", kSource / "data/scenes");
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(DatasetSimulation, CalibrationSceneErrorsNameLineAndField) {
  const std::string galvo =
      "uwscan_format: 1\n"                                 // 1
      "scanner: {file: ../scanners/galvo_default.yaml}\n"  // 2
      "calibration:\n"                                     // 3
      "  step: laser\n"                                    // 4
      "  pattern: {type: chessboard, columns: 9, rows: 6, square_m: 0.04}\n"
      "  mirror_steps: [-50, 50]\n";  // 6
  EXPECT_EQ(SceneError(galvo), "(no error)");
  std::string text = galvo;
  text.replace(text.find("step: laser"), 11, "step: lazer");
  EXPECT_NE(SceneError(text).find("test.yaml:4: field 'calibration.step': got 'lazer'"),
            std::string::npos)
      << SceneError(text);
  EXPECT_NE(SceneError(galvo + "  views: 5\n")
                .find("test.yaml:7: field 'calibration.views': not used by a laser step"),
            std::string::npos)
      << SceneError(galvo + "  views: 5\n");
  text = galvo;
  text.replace(text.find("[-50, 50]"), 9, "[-50, 150]");
  EXPECT_NE(SceneError(text).find("test.yaml:6: field 'calibration.mirror_steps[1]': mirror step "
                                  "150 outside the laser's range [-100, 100]"),
            std::string::npos)
      << SceneError(text);
  text = galvo;
  text.replace(text.find("galvo_default"), 13, "mems_default");
  text.replace(text.find("  mirror_steps: [-50, 50]\n"), 26, "");
  EXPECT_NE(SceneError(text).find("a laser step needs a galvanometer scanner"), std::string::npos)
      << SceneError(text);
  EXPECT_NE(SceneError(galvo + "objects: []\n").find("test.yaml:7: field 'objects'"),
            std::string::npos)
      << SceneError(galvo + "objects: []\n");
  // The scene reader's own messages still point at the user's lines.
  const std::string effects = galvo + "effects:\n  image: {format: mono12}\n";
  EXPECT_NE(SceneError(effects).find("test.yaml:8: field 'effects.image.format'"),
            std::string::npos)
      << SceneError(effects);
  EXPECT_NE(SceneError(galvo + "  render: {supersampling: 0}\n").find("supersampling"),
            std::string::npos);
  const std::string no_section =
      "uwscan_format: 1\nscanner: {file: ../scanners/galvo_default.yaml}\n";
  EXPECT_NE(SceneError(no_section).find("field 'calibration': missing"), std::string::npos)
      << SceneError(no_section);
}

TEST(DatasetSimulation, ScenesChangedInCodeAreCheckedToo) {
  CalibrationScene scene = LoadCalibrationScene(kSource / "data/scenes/calib_laser.yaml");
  EXPECT_NO_THROW(scene.Check());
  auto error = [](const CalibrationScene& s) {
    try {
      SimulateCalibrationDataset(s, OutFolder("never_written"));
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  CalibrationScene changed = scene;
  changed.mirror_steps = {-120, 0};
  EXPECT_NE(error(changed).find("calibration.mirror_steps: expected steps in the laser's range"),
            std::string::npos)
      << error(changed);
  changed = scene;
  changed.image_scale = 0.0;
  EXPECT_NE(error(changed).find("calibration.image_scale"), std::string::npos);
  changed = scene;
  changed.step = "mems";
  EXPECT_NE(error(changed).find("calibration.step"), std::string::npos);
  changed = scene;
  changed.board_size_m = Eigen::Vector2d(0.3, 0.3);  // smaller than the pattern
  EXPECT_NE(error(changed).find("calibration.board_size_m"), std::string::npos);
  EXPECT_FALSE(fs::exists(OutFolder("never_written")));
}

// The shipped calibration scenes all simulate (here small: half-size images, few poses).
TEST(DatasetSimulation, ShippedScenesSimulate) {
  for (const char* name : {"calib_intrinsics", "calib_viewport", "calib_laser",
                           "calib_laser_viewport", "calib_mems"}) {
    CalibrationScene scene =
        LoadCalibrationScene(kSource / "data/scenes" / (std::string(name) + ".yaml"));
    scene.image_scale = 0.5;
    scene.views = 3;
    scene.planes = 2;
    scene.volts_grid = Eigen::Vector2i(5, 5);
    const fs::path out = OutFolder(name);
    SimulateCalibrationDataset(scene, out);
    const CalibrationDataset d = LoadCalibrationDataset(out);
    EXPECT_EQ(d.step, scene.step) << name;
    EXPECT_EQ(
        d.views.size() + d.planes.size(),
        name == std::string("calib_intrinsics") || name == std::string("calib_viewport") ? 3u : 2u)
        << name;
  }
}

}  // namespace
}  // namespace uwscan::scanner::calibration
