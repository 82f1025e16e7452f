#include "scanner/sim/scene.hpp"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/lasers/galvo_scanner_model.hpp"
#include "scanner/sim/imr_objects.hpp"

namespace uwscan::scanner::sim {
namespace {

const std::filesystem::path kSourceDir = UWSCAN_SOURCE_DIR_FOR_TESTS;
const std::filesystem::path kData = kSourceDir / "data";

// A scene whose scanner is the default galvo scanner, given by absolute path so that the
// scene may be parsed from anywhere; `body` follows the scanner section.
std::string SceneText(const std::string& body, const std::string& scanner_extra = "") {
  return "uwscan_format: 1\nscanner:\n  file: " +
         (kData / "scanners" / "galvo_default.yaml").string() + "\n" + scanner_extra + body;
}

const char* const kPlaneObject = R"(objects:
  - {shape: plane, size_m: [3, 3]}
)";

Scene Parse(const std::string& text) { return ParseScene(text, "scene.yaml", kData / "scenes"); }

// The message of the uwscan::Error that parsing `text` throws ("" when it does not throw).
std::string ParseError(const std::string& text) {
  try {
    Parse(text);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "in: " << (text)

TEST(SceneParse, MinimalSceneTakesDefaults) {
  const Scene s = Parse(SceneText(kPlaneObject));
  EXPECT_EQ(s.source, "scene.yaml");
  EXPECT_EQ(s.seed, 1u);
  EXPECT_EQ(s.water.refractive_index, 1.33);
  EXPECT_EQ(s.scanner.model.kind(), ScannerKind::kGalvo);
  EXPECT_EQ(s.scanner.galvo.step_min, -100);  // the laser's range
  EXPECT_EQ(s.scanner.galvo.step_max, 100);
  EXPECT_EQ(s.scanner.sweeps, 1);
  EXPECT_EQ(s.scanner.model.laser_viewport().thickness_m,
            DefaultGalvoScannerModel().laser.viewport.thickness_m);
  ASSERT_EQ(s.trajectory.poses.size(), 1u);
  EXPECT_TRUE(s.trajectory.T_W_C(0.0).isApprox(Eigen::Isometry3d::Identity()));
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_EQ(s.objects[0].name, "plane_0");
  EXPECT_EQ(s.objects[0].mesh.triangles.size(), 2u);
  EXPECT_TRUE(s.effects.refraction);
  EXPECT_FALSE(s.effects.AnyImageStage());
}

TEST(SceneParse, EverySectionRead) {
  const std::string text = SceneText(R"(seed: 42
water: {refractive_index: 1.34, attenuation_per_m: 0.3}
trajectory:
  T_V_C: {translation_m: [0.1, 0, 0], rotation_xyzw: [0, 0, 0, 1]}
  poses:
    - {time_s: 0, T_W_V: {translation_m: [0, 0, 0], rotation_xyzw: [0, 0, 0, 1]}}
    - {time_s: 2, T_W_V: {translation_m: [1, 0, 0], rotation_xyzw: [0, 0, 0, 1]}}
effects:
  refraction: false
  lens_distortion: false
  occlusion: true
  motion: true
  navigation_drift: {position_walk_m_per_sqrt_s: 0.01}
  image: {format: mono16, peak_level: 3000, blur_sigma_px: 1.2}
  beam: true
  sensor_noise: {on: false, read_sigma: 2}
  speckle: {contrast: 0.2}
  attenuation: true
  backscatter: {level: 5}
  ambient: false
detector: {method: centre_of_mass, axis: rows, threshold: 30, window_px: 9}
objects:
  - {name: seabed, shape: plane, size_m: [3, 2], reflectance: 0.3,
     pose: {translation_m: [0, 0, 1.3], rotation_xyzw: [1, 0, 0, 0]}}
  - {shape: box, size_m: [0.1, 0.2, 0.3]}
  - {shape: sphere, radius_m: 0.1}
  - {shape: cylinder, radius_m: 0.05, length_m: 0.2, chord_error_m: 0.001}
  - {shape: pipe, outer_radius_m: 0.06, wall_m: 0.006, length_m: 0.5}
  - {shape: elbow, bend_radius_m: 0.15, bend_angle_rad: 1.0}
  - {shape: tee}
  - {shape: flange, bolts: 6}
  - {shape: valve, handle: lever}
  - {name: g50, shape: gauge, length_m: 0.05}
)",
                                     "  sweeps: 2\n  galvo: {step_min: -50, step_max: 60, "
                                     "step_stride: 2, frame_rate_hz: 100}\n");
  const Scene s = Parse(text);
  EXPECT_EQ(s.seed, 42u);
  EXPECT_EQ(s.water.refractive_index, 1.34);
  EXPECT_EQ(s.water.attenuation_per_m, 0.3);
  EXPECT_EQ(s.scanner.sweeps, 2);
  EXPECT_EQ(s.scanner.galvo.step_min, -50);
  EXPECT_EQ(s.scanner.galvo.step_max, 60);
  EXPECT_EQ(s.scanner.galvo.step_stride, 2);
  EXPECT_EQ(s.scanner.galvo.frame_rate_hz, 100.0);
  EXPECT_EQ(s.trajectory.poses.size(), 2u);
  EXPECT_EQ(s.trajectory.T_V_C.translation().x(), 0.1);
  EXPECT_EQ(s.trajectory.T_W_V(1.0).translation().x(), 0.5);

  const SimulationEffects& e = s.effects;
  EXPECT_FALSE(e.refraction);
  EXPECT_FALSE(e.lens_distortion);
  EXPECT_TRUE(e.motion);
  EXPECT_FALSE(e.mirror_dynamics);
  EXPECT_TRUE(e.navigation_drift.on);
  EXPECT_EQ(e.navigation_drift.position_walk_m_per_sqrt_s, 0.01);
  EXPECT_EQ(e.navigation_drift.yaw_walk_rad_per_sqrt_s, 0.0005);
  EXPECT_TRUE(e.image.on);
  EXPECT_EQ(e.image.format, PixelFormat::kMono16);
  EXPECT_EQ(e.image.peak_level, 3000.0);
  EXPECT_EQ(e.image.blur_sigma_px, 1.2);
  EXPECT_TRUE(e.beam.on);
  EXPECT_FALSE(e.sensor_noise.on);
  EXPECT_EQ(e.sensor_noise.read_sigma, 2.0);
  EXPECT_TRUE(e.speckle.on);
  EXPECT_TRUE(e.attenuation);
  EXPECT_TRUE(e.backscatter.on);
  EXPECT_EQ(e.backscatter.level, 5.0);
  EXPECT_FALSE(e.ambient.on);

  EXPECT_EQ(s.detector.method, StripeMethod::kCentreOfMass);
  EXPECT_EQ(s.detector.axis, StripeAxis::kRows);
  EXPECT_EQ(s.detector.threshold, 30);
  EXPECT_EQ(s.detector.window_px, 9);

  ASSERT_EQ(s.objects.size(), 10u);
  EXPECT_EQ(s.objects[0].name, "seabed");
  EXPECT_EQ(s.objects[0].reflectance, 0.3);
  EXPECT_TRUE(
      (s.objects[0].T_W_O.linear() * Eigen::Vector3d::UnitZ()).isApprox(-Eigen::Vector3d::UnitZ()));
  EXPECT_EQ(s.objects[1].name, "box_1");
  EXPECT_EQ(s.objects[2].shape, ObjectShape::kSphere);
  EXPECT_EQ(s.objects[2].sphere_radius_m, 0.1);
  EXPECT_TRUE(s.objects[2].mesh.triangles.empty());
  EXPECT_EQ(s.objects[3].mesh.vertices.size(),
            2u + 2u * static_cast<size_t>(CircleSegments(0.05, 0.001)));
  EXPECT_EQ(s.objects[9].shape, ObjectShape::kGauge);
  EXPECT_EQ(s.objects[9].gauge_length_m, 0.05);
  for (const SceneObject& o : s.objects) {
    if (o.shape != ObjectShape::kSphere) {
      EXPECT_FALSE(o.mesh.triangles.empty()) << o.name;
    }
  }
}

TEST(SceneParse, MeshObjectsAreLoadedAndScaled) {
  const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "uwscan_scene_mesh";
  std::filesystem::create_directories(dir);
  WriteMeshPly(MakeBox({1.0, 2.0, 3.0}), dir / "box.ply");
  const std::string text = SceneText("objects:\n  - {shape: mesh, file: box.ply, scale: 0.001}\n");
  const Scene s = ParseScene(text, "scene.yaml", dir);
  ASSERT_EQ(s.objects.size(), 1u);
  EXPECT_NEAR(s.objects[0].mesh.BoundingBoxDiagonal(), std::sqrt(14.0) * 0.001, 1e-9);
  EXPECT_CONTAINS(ParseError(SceneText("objects:\n  - {shape: mesh, file: missing.ply}\n")),
                  "field 'objects[0].file'");
  std::filesystem::remove_all(dir);
}

TEST(SceneParse, EffectSwitchesAndSettings) {
  auto effects = [](const std::string& body) {
    return Parse(SceneText("effects:\n" + body + std::string(kPlaneObject))).effects;
  };
  EXPECT_TRUE(effects("  image: true\n").image.on);
  EXPECT_FALSE(effects("  image: false\n").image.on);
  EXPECT_FALSE(effects("  image: {on: false, peak_level: 100}\n").image.on);
  EXPECT_EQ(effects("  image: {on: false, peak_level: 100}\n").image.peak_level, 100.0);
  EXPECT_TRUE(effects("  ambient: {}\n").ambient.on);
  EXPECT_FALSE(effects("  occlusion: false\n").occlusion);
  EXPECT_TRUE(effects("  attenuation: true\n").AnyImageStage());
}

TEST(SceneParse, ErrorsNameTheLineAndField) {
  // Line numbers count from the scene's first line: uwscan_format, scanner, file, then body.
  EXPECT_CONTAINS(ParseError(SceneText("wather: {}\n" + std::string(kPlaneObject))),
                  "scene.yaml:4: field 'wather': unknown field");
  EXPECT_CONTAINS(ParseError(SceneText(R"(objects:
  - {shape: plane, size_m: [3, 3]}
  - {shape: sphere, radius_m: 0.1, reflectance: 1.5}
)")),
                  "scene.yaml:6: field 'objects[1].reflectance': got 1.5, expected in [0, 1]");
  EXPECT_CONTAINS(ParseError(SceneText(R"(objects:
  - {shape: sphere, radius_m: 0.1, colour: red}
)")),
                  "field 'objects[0].colour': unknown field");
  EXPECT_CONTAINS(ParseError(SceneText(R"(objects:
  - {name: a, shape: sphere, radius_m: 0.1}
  - {name: a, shape: sphere, radius_m: 0.2}
)")),
                  "field 'objects[1].name': duplicate object name 'a' (also objects[0])");
  EXPECT_CONTAINS(ParseError(SceneText("objects:\n  - {shape: cone}\n")),
                  "field 'objects[0].shape': got 'cone', expected one of plane, box");
  EXPECT_CONTAINS(ParseError(SceneText("objects:\n  - {shape: pipe, wall_m: 0.06}\n")),
                  "field 'objects[0]': PipeShape.wall_m");
  EXPECT_CONTAINS(ParseError(SceneText("objects:\n  - {shape: sphere, radius_m: -1}\n")),
                  "field 'objects[0].radius_m': got -1, expected > 0");
  EXPECT_CONTAINS(ParseError(SceneText("objects: []\n")), "field 'objects'");
  EXPECT_CONTAINS(
      ParseError(SceneText("water: {refractive_index: 0.9}\n" + std::string(kPlaneObject))),
      "field 'water.refractive_index': got 0.9, expected >= 1");
  EXPECT_CONTAINS(
      ParseError(SceneText("effects: {image: {blur_sigma_px: 0}}\n" + std::string(kPlaneObject))),
      "field 'effects.image.blur_sigma_px'");
  EXPECT_CONTAINS(ParseError(SceneText("effects: {image: maybe}\n" + std::string(kPlaneObject))),
                  "field 'effects.image': expected true or false");
  EXPECT_CONTAINS(
      ParseError(SceneText("effects: {speckle: {contrst: 1}}\n" + std::string(kPlaneObject))),
      "field 'effects.speckle.contrst': unknown field");
  EXPECT_CONTAINS(ParseError(SceneText("detector: {method: best}\n" + std::string(kPlaneObject))),
                  "field 'detector.method': got 'best'");
  EXPECT_CONTAINS(ParseError(SceneText("detector: {window_px: 4}\n" + std::string(kPlaneObject))),
                  "field 'detector': StripeDetectorOptions.window_px");
  EXPECT_CONTAINS(ParseError(SceneText(R"(trajectory:
  poses:
    - {time_s: 1, T_W_V: {translation_m: [0, 0, 0], rotation_xyzw: [0, 0, 0, 1]}}
    - {time_s: 1, T_W_V: {translation_m: [1, 0, 0], rotation_xyzw: [0, 0, 0, 1]}}
)" + std::string(kPlaneObject))),
                  "scene.yaml:7: field 'trajectory.poses[1].time_s': got 1 s, expected later");
  EXPECT_CONTAINS(ParseError(SceneText(kPlaneObject, "  galvo: {step_min: -200}\n")),
                  "field 'scanner.galvo.step_min': got -200, expected in [-100, 100]");
  EXPECT_CONTAINS(ParseError(SceneText(kPlaneObject, "  mems: {lines: 10}\n")),
                  "field 'scanner.mems': the scanner file has no top-level 'mems:'");
  EXPECT_CONTAINS(ParseError("uwscan_format: 2\n"), "uwscan_format");
  EXPECT_CONTAINS(ParseError("uwscan_format: 1\nobjects: [\n"), "scene.yaml:");
}

TEST(SceneParse, MissingScannerFileNamesFieldAndPath) {
  const std::string text = "uwscan_format: 1\nscanner: {file: ../scanners/nonexistent.yaml}\n" +
                           std::string(kPlaneObject);
  const std::string message = ParseError(text);
  EXPECT_CONTAINS(message, "scene.yaml:2: field 'scanner.file'");
  EXPECT_CONTAINS(message, (kData / "scanners" / "nonexistent.yaml").string());
}

TEST(SceneParse, MemsScannerFromTheFile) {
  // The top-level `mems:` key decides the kind; the whole file is read with the scene.
  const std::filesystem::path dir = std::filesystem::path(testing::TempDir()) / "uwscan_scene_mems";
  std::filesystem::create_directories(dir);
  {
    std::ofstream out(dir / "mems.yaml");
    std::ifstream in(std::string(UWSCAN_SOURCE_DIR_FOR_TESTS) + "/data/scanners/mems_default.yaml");
    out << in.rdbuf();
  }
  const std::string body = std::string(kPlaneObject);
  const Scene s = ParseScene(
      "uwscan_format: 1\nscanner:\n  file: mems.yaml\n  mems: {lines: 20, waypoints_per_line: 30, "
      "fov_fraction: [0.5, 1]}\n" +
          body,
      "scene.yaml", dir);
  EXPECT_EQ(s.scanner.model.kind(), ScannerKind::kMems);
  EXPECT_EQ(s.scanner.mems.lines, 20);
  EXPECT_EQ(s.scanner.mems.waypoints_per_line, 30);
  EXPECT_EQ(s.scanner.mems.fov_fraction_x, 0.5);
  EXPECT_EQ(s.scanner.file, (dir / "mems.yaml").lexically_normal());
  try {
    ParseScene("uwscan_format: 1\nscanner:\n  file: mems.yaml\n  galvo: {step_min: 0}\n" + body,
               "scene.yaml", dir);
    FAIL();
  } catch (const Error& e) {
    EXPECT_CONTAINS(e.what(), "field 'scanner.galvo': the scanner file has a top-level 'mems:'");
  }
  try {
    ParseScene(
        "uwscan_format: 1\nscanner:\n  file: mems.yaml\n  mems: {fov_fraction: [0, 1]}\n" + body,
        "scene.yaml", dir);
    FAIL();
  } catch (const Error& e) {
    EXPECT_CONTAINS(e.what(), "field 'scanner.mems.fov_fraction'");
  }
  std::filesystem::remove_all(dir);
}

TEST(SceneParse, LoadSceneResolvesAgainstItsFolder) {
  EXPECT_THROW(LoadScene(kData / "scenes" / "no_such_scene.yaml"), Error);
  const Scene s = LoadScene(kData / "scenes" / "default.yaml");
  EXPECT_EQ(s.scanner.file, (kData / "scanners" / "galvo_default.yaml").lexically_normal());
}

// Every shipped dive scene parses (calibration scenes, with a `calibration:` section, are
// parsed by the calibration tests).
TEST(SceneParse, EveryDataSceneParses) {
  int parsed = 0;
  for (const auto& entry : std::filesystem::directory_iterator(kData / "scenes")) {
    if (entry.path().extension() != ".yaml") continue;
    const YAML::Node root = YAML::LoadFile(entry.path().string());
    if (root["calibration"]) continue;
    const std::filesystem::path scanner =
        entry.path().parent_path() / root["scanner"]["file"].as<std::string>();
    ASSERT_TRUE(std::filesystem::exists(scanner)) << scanner;
    try {
      const Scene s = LoadScene(entry.path());
      EXPECT_FALSE(s.objects.empty());
      ++parsed;
    } catch (const Error& e) {
      ADD_FAILURE() << e.what();
    }
  }
  EXPECT_GE(parsed, 3);
}

TEST(SceneEffects, CheckNamesTheField) {
  SimulationEffects e;
  e.Check();
  e.speckle.contrast = 1.5;
  try {
    e.Check();
    FAIL();
  } catch (const Error& error) {
    EXPECT_CONTAINS(error.what(), "speckle.contrast");
  }
  e = SimulationEffects{};
  e.beam.divergence_rad = -0.1;
  EXPECT_THROW(e.Check(), Error);
  e = SimulationEffects{};
  e.sensor_noise.electrons_per_level = 0.0;
  EXPECT_THROW(e.Check(), Error);
}

TEST(SceneParse, ShapeNamesRoundTrip) {
  EXPECT_STREQ(ToString(ObjectShape::kGauge), "gauge");
  EXPECT_STREQ(ToString(ObjectShape::kTee), "tee");
}

}  // namespace
}  // namespace uwscan::scanner::sim
