// The dive commands end to end: simulate, reconstruct, demo, make-object, bench accuracy.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "tests/cli_run.hpp"

namespace {

using uwscan::test::CommandRun;
using uwscan::test::RunUwscan;

std::filesystem::path TempPath(const std::string& name) { return uwscan::test::ScratchPath(name); }

nlohmann::json ReadJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

std::string SourcePath(const std::string& relative) {
  return std::string(UWSCAN_SOURCE_DIR) + "/" + relative;
}

TEST(CliDive, SimulateThenReconstructRecoversTheSceneWithEveryMethod) {
  const std::filesystem::path log = TempPath("default.db");
  const CommandRun sim =
      RunUwscan("simulate " + SourcePath("data/scenes/default.yaml") + " -o " + log.string());
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  EXPECT_NE(sim.output.find("201 frames"), std::string::npos) << sim.output;

  // ray-ray is exact, ray-cone within the seed's 0.05 mm, ray-plane off by millimetres.
  const std::array<std::pair<const char*, double>, 3> bounds = {
      {{"ray", 1e-6}, {"cone", 5e-5}, {"plane", 1.0}}};
  for (const auto& [method, max_mean_m] : bounds) {
    const std::filesystem::path cloud = TempPath(std::string(method) + ".ply");
    const std::filesystem::path json = TempPath(std::string(method) + ".json");
    const CommandRun run = RunUwscan("reconstruct " + log.string() + " -o " + cloud.string() +
                                     " --method " + method + " --json " + json.string());
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const nlohmann::json j = ReadJson(json);
    EXPECT_GT(j["points"].get<int>(), 100000) << method;
    EXPECT_LT(j["truth_error"]["mean_m"].get<double>(), max_mean_m) << method;
    EXPECT_GT(std::filesystem::file_size(cloud), 1000000u) << method;
    std::filesystem::remove(cloud);
    std::filesystem::remove(json);
  }
  // A log is never overwritten by accident.
  const CommandRun again =
      RunUwscan("simulate " + SourcePath("data/scenes/default.yaml") + " -o " + log.string());
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_NE(again.output.find("exists"), std::string::npos) << again.output;
  std::filesystem::remove(log);
}

// A dive log `map` cannot use: the reason on one line, exit 1, no map written.
TEST(CliDive, MapRefusesAnUnusableLogWithOneLine) {
  const std::filesystem::path log = TempPath("short.db"), map = TempPath("map.ply");
  const CommandRun simulated =
      RunUwscan("simulate " + SourcePath("data/scenes/inspection_short.yaml") + " -o " +
                log.string() + " --force");
  ASSERT_EQ(simulated.exit_code, 0) << simulated.output;
  // Each damage applied to a fresh copy of the log.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"DELETE FROM navigation", "has no navigation"},
      {"DELETE FROM ground_truth WHERE frame_index > 0; DELETE FROM frames WHERE frame_index > 0",
       "has 1 frame"},
      {"UPDATE meta SET value = 99 WHERE key = 'schema_version'",
       "has schema version 99, this uwscan reads 1 to"}};
  for (const auto& [sql, reason] : cases) {
    const std::filesystem::path copy = TempPath("damaged.db");
    std::filesystem::copy_file(log, copy, std::filesystem::copy_options::overwrite_existing);
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(copy.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK) << sql;
    sqlite3_close(db);
    const CommandRun run = RunUwscan("map " + copy.string() + " -o " + map.string());
    EXPECT_EQ(run.exit_code, 1) << sql << "\n" << run.output;
    EXPECT_NE(run.output.find(reason), std::string::npos) << sql << "\n" << run.output;
    EXPECT_NE(run.output.find(copy.string()), std::string::npos)
        << "the log is named: " << run.output;
    EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1)
        << "one line: " << run.output;
    EXPECT_FALSE(std::filesystem::exists(map)) << sql;
    std::filesystem::remove(copy);
  }
  // A real log (no ground truth) asked for the true trajectory: refused before any output.
  const std::filesystem::path copy = TempPath("real.db"), truth = TempPath("truth.tum");
  std::filesystem::copy_file(log, copy, std::filesystem::copy_options::overwrite_existing);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(copy.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "DELETE FROM ground_truth", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  const CommandRun run =
      RunUwscan("map " + copy.string() + " -o " + map.string() + " --truth " + truth.string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("holds no ground truth"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(map));
  EXPECT_FALSE(std::filesystem::exists(truth));
  std::filesystem::remove(copy);
  std::filesystem::remove(log);
}

// bench slam --long with two seeds: one dive per length and seed, each its own drift draw, the
// windowed and whole-graph runs on the same dive, and the layout issue 52 asks for.
TEST(CliDive, LongSlamBenchDivesOncePerSeed) {
  const std::filesystem::path json = TempPath("slam_long.json");
  const CommandRun run =
      RunUwscan("bench slam --long --minutes 0.3 --seeds 2 --json " + json.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("over the seeds"), std::string::npos) << run.output;
  const nlohmann::json j = ReadJson(json);
  ASSERT_EQ(j["dives"].size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    const nlohmann::json& d = j["dives"][k];
    EXPECT_EQ(d["name"], "manifold_0.3min");
    EXPECT_EQ(d["seed"].get<int>(), 41 + static_cast<int>(k));
    ASSERT_TRUE(d["full_solve"].is_object());
    for (const char* figure : {"ate_m", "map_rms_m", "real_time_factor"})
      EXPECT_GT(d[figure].get<double>(), 0.0) << figure;
    EXPECT_GT(d["submap_seconds"]["last_tenth"]["median"].get<double>(), 0.0);
    // The accepted loops the truth puts off: counted, and part of the accepted.
    ASSERT_TRUE(d["loops_false"].is_number_integer());
    EXPECT_GE(d["loops_false"].get<int>(), 0);
    EXPECT_LE(d["loops_false"].get<int>(), d["loops_accepted"].get<int>());
  }
  EXPECT_NE(j["dives"][0]["dead_reckoning_ate_m"].get<double>(),
            j["dives"][1]["dead_reckoning_ate_m"].get<double>());
  std::filesystem::remove(json);
}

// bench slam on the short test lap: every figure issue 10 asks of a dive is in the JSON, and
// the ones with a ground truth to hold them to are sane.
TEST(CliDive, SlamBenchWritesEveryFigureOfADive) {
  const std::filesystem::path json = TempPath("slam.json");
  const CommandRun run =
      RunUwscan("bench slam --scene " + SourcePath("data/scenes/inspection_short.yaml") +
                " --seeds 1 --json " + json.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json j = ReadJson(json);
  ASSERT_EQ(j["dives"].size(), 1u);
  const nlohmann::json& d = j["dives"][0];
  EXPECT_EQ(d["name"], "inspection_short");
  EXPECT_NEAR(d["duration_s"].get<double>(), 20.0, 0.5);
  for (const char* part : {"dr", "slam", "open3d"}) {
    ASSERT_TRUE(d[part].is_object()) << part << " (Open3D is a build dependency)";
    for (const char* figure : {"ate_m", "rpe_per_m", "map_rms_m", "seconds"}) {
      ASSERT_TRUE(d[part][figure].is_number()) << part << "." << figure;
      EXPECT_GE(d[part][figure].get<double>(), 0.0) << part << "." << figure;
    }
  }
  const nlohmann::json& slam = d["slam"];
  EXPECT_EQ(slam["loops_false"].get<int>(), 0);
  EXPECT_GE(slam["loops_accepted"].get<int>(), 0);
  EXPECT_GT(slam["nees_mean"].get<double>(), 0.0);
  EXPECT_GT(slam["real_time_factor"].get<double>(), 0.0);
  // The drift is millimetres to centimetres on a 20 s lap; the map lies within millimetres of
  // the true surfaces, and above the floor of the frames placed at their true poses.
  EXPECT_GT(d["dr"]["ate_m"].get<double>(), 1e-3);
  EXPECT_LT(slam["ate_m"].get<double>(), 0.05);
  EXPECT_LT(slam["map_rms_m"].get<double>(), 0.01);
  EXPECT_GT(slam["map_rms_m"].get<double>(), d["true_poses_map"]["rms_m"].get<double>());
  ASSERT_EQ(j["summary"].size(), 1u);
  EXPECT_EQ(j["summary"][0]["seeds"].get<int>(), 1);
  std::filesystem::remove(json);
}

std::string FileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// `map` writes the same bits whatever the thread count, and from one process to the next (the
// covariances once came out of a sparse QR whose rounding followed heap addresses).
TEST(CliDive, MapWritesTheSameBitsOnOneOrTwoThreadsAndInEveryRun) {
  const std::filesystem::path log = TempPath("bits.db");
  const CommandRun simulated =
      RunUwscan("simulate " + SourcePath("data/scenes/inspection_short.yaml") + " -o " +
                log.string() + " --force");
  ASSERT_EQ(simulated.exit_code, 0) << simulated.output;
  struct Output {
    std::string map, trajectory;
    nlohmann::json report;
  };
  auto map = [&](int threads) {
    const std::filesystem::path ply = TempPath("bits.ply"), tum = TempPath("bits.tum"),
                                json = TempPath("bits.json");
    const CommandRun run =
        RunUwscan("map " + log.string() + " -o " + ply.string() + " --trajectory " + tum.string() +
                  " --json " + json.string() + " --threads " + std::to_string(threads));
    EXPECT_EQ(run.exit_code, 0) << run.output;
    Output out{FileBytes(ply), FileBytes(tum), ReadJson(json)};
    for (const char* timing : {"seconds", "real_time_factor"}) out.report["figures"].erase(timing);
    for (const auto& path : {ply, tum, json}) std::filesystem::remove(path);
    return out;
  };
  const Output one = map(1), two = map(2), again = map(2);
  ASSERT_FALSE(one.map.empty());
  ASSERT_TRUE(one.report.contains("pose_covariance"));
  for (const Output* other : {&two, &again}) {
    EXPECT_TRUE(other->map == one.map);
    EXPECT_TRUE(other->trajectory == one.trajectory);
    // Doubles are written to the last bit, so equal JSON is equal bits.
    EXPECT_TRUE(other->report == one.report)
        << nlohmann::json::diff(one.report, other->report).dump().substr(0, 2000);
  }
  std::filesystem::remove(log);
}

TEST(CliDive, MalformedSceneNamesTheFileLineAndField) {
  const std::filesystem::path dir = TempPath("scenes");
  std::filesystem::create_directories(dir / "scenes");
  std::filesystem::copy_file(SourcePath("data/scanners/galvo_default.yaml"), dir / "galvo.yaml");
  const std::filesystem::path scene = dir / "scenes" / "bad.yaml";
  std::ofstream(scene) << "uwscan_format: 1\n"
                          "scanner: {file: ../galvo.yaml}\n"
                          "objects:\n"
                          "  - {shape: sphere, radius_m: 0.1, reflectance: 1.5}\n";
  const CommandRun run = RunUwscan("simulate " + scene.string() + " -o " + (dir / "x.db").string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("bad.yaml:4"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("reflectance"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "x.db"));
  std::filesystem::remove_all(dir);
}

TEST(CliDive, ReconstructRejectsWhatIsNotADiveLog) {
  const std::filesystem::path junk = TempPath("junk.db");
  std::ofstream(junk) << "this is not a dive log";
  const CommandRun run =
      RunUwscan("reconstruct " + junk.string() + " -o " + TempPath("x.ply").string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find(junk.string()), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(TempPath("x.ply")));
  std::filesystem::remove(junk);
}

TEST(CliDive, DemoPrintsEveryMethodAgainstTruth) {
  const CommandRun run = RunUwscan("demo --scene " + SourcePath("data/scenes/default.yaml"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  for (const char* method : {"ray_plane", "ray_cone", "ray_ray"}) {
    EXPECT_NE(run.output.find(method), std::string::npos) << method;
  }
}

// Without --scene, from a folder that is not the repository root, demo finds the default scene
// in the source tree it was built from.
TEST(CliDive, DemoWithoutASceneRunsFromAnyFolder) {
  const std::filesystem::path elsewhere = TempPath("demo_elsewhere");
  std::filesystem::create_directories(elsewhere);
  const CommandRun run = uwscan::test::RunCommand("cd " + elsewhere.string() + " && " +
                                                  std::string(UWSCAN_BIN) + " demo");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("default.yaml"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("ray_ray"), std::string::npos) << run.output;
  std::filesystem::remove_all(elsewhere);
}

TEST(CliDive, MakeObjectWritesAReadableMesh) {
  const std::filesystem::path mesh = TempPath("valve.ply");
  const CommandRun run = RunUwscan("make-object valve -o " + mesh.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_GT(std::filesystem::file_size(mesh), 1000u);
  const CommandRun bad = RunUwscan("make-object teapot -o " + mesh.string());
  EXPECT_NE(bad.exit_code, 0);
  std::filesystem::remove(mesh);
}

// A size in millimetres where metres are expected (a 300 m pipe) is refused, naming the option,
// and nothing is written.
TEST(CliDive, MakeObjectRefusesASizeInMillimetres) {
  const std::filesystem::path mesh = TempPath("pipe.ply");
  std::filesystem::remove(mesh);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"pipe --length-m 300", "--length-m"},
      {"box --size-m 0.1 0.2 150", "--size-m"},
      {"valve --handle-radius-m 0", "--handle-radius-m"}};
  for (const auto& [options, option] : cases) {
    const CommandRun run = RunUwscan("make-object " + options + " -o " + mesh.string());
    EXPECT_NE(run.exit_code, 0) << options;
    EXPECT_NE(run.output.find(option), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("metres"), std::string::npos) << run.output;
    EXPECT_FALSE(std::filesystem::exists(mesh)) << options;
  }
  ASSERT_EQ(RunUwscan("make-object pipe --length-m 0.3 -o " + mesh.string()).exit_code, 0);
  std::filesystem::remove(mesh);
}

TEST(CliDive, SimulationBenchTimesEveryEffectAndOffStagesChangeNothing) {
  const std::filesystem::path json = TempPath("simulation.json");
  const CommandRun run = RunUwscan("bench simulation --frames 2 --data " + SourcePath("data") +
                                   " --json " + json.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json rows = ReadJson(json).at("rows");
  std::map<std::string, nlohmann::json> galvo, mems;
  for (const nlohmann::json& row : rows) {
    (row["scene"] == "galvo" ? galvo : mems)[row["effect"].get<std::string>()] = row;
    EXPECT_GT(row["ms_per_frame"].get<double>(), 0.0);
  }
  for (const char* effect :
       {"none", "refraction", "lens_distortion", "occlusion", "motion", "navigation_drift", "image",
        "beam", "sensor_noise", "speckle", "attenuation", "backscatter", "ambient",
        "off_with_parameters", "all"}) {
    EXPECT_TRUE(galvo.contains(effect)) << effect;
    EXPECT_TRUE(mems.contains(effect)) << effect;
  }
  EXPECT_TRUE(mems.contains("mirror_dynamics"));
  // Stages left off with changed parameters produce exactly the all-off frames.
  EXPECT_EQ(galvo["off_with_parameters"]["peaks"], galvo["none"]["peaks"]);
  EXPECT_EQ(mems["off_with_parameters"]["peaks"], mems["none"]["peaks"]);
  std::filesystem::remove(json);
}

TEST(CliDive, AccuracyBenchWritesEveryTable) {
  const std::filesystem::path json = TempPath("accuracy.json");
  const CommandRun run =
      RunUwscan("bench accuracy --quick --data " + SourcePath("data") + " --json " + json.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json j = ReadJson(json);
  for (const char* medium : {"air", "water"}) {
    EXPECT_GT(j["gauges"][medium]["n"].get<int>(), 0) << medium;
    // Sub-millimetre gauge lengths with realistic noise (seed: 0.44 mm air, 0.98 mm water).
    EXPECT_LT(j["gauges"][medium]["mean_err_m"].get<double>(), 1e-3) << medium;
  }
  ASSERT_FALSE(j["plane"].empty());
  EXPECT_LT(j["plane"][0]["rms_m"].get<double>(), 2e-3);
  ASSERT_FALSE(j["sphere"].empty());
  EXPECT_LT(std::abs(j["sphere"][0]["radius_err_m"].get<double>()), 2e-3);
  ASSERT_EQ(j["waypoints"].size(), 2u);
  // More waypoints per line: slower lines.
  EXPECT_GT(j["waypoints"][0]["lines_per_s"].get<double>(),
            j["waypoints"][1]["lines_per_s"].get<double>());
  // The detector's error on the rendered stripes: sub-pixel and centred.
  for (const char* stripes : {"gauges_water", "plane"}) {
    const nlohmann::json& p = j["peak_errors"][stripes];
    EXPECT_GT(p["peaks"].get<long long>(), 1000) << stripes;
    EXPECT_GT(p["std_px"].get<double>(), 0.02) << stripes;
    EXPECT_LT(p["std_px"].get<double>(), 0.5) << stripes;
    EXPECT_LT(std::abs(p["bias_px"].get<double>()), 0.2 * p["std_px"].get<double>()) << stripes;
    EXPECT_GT(p["p95_abs_px"].get<double>(), p["std_px"].get<double>()) << stripes;
  }
  std::filesystem::remove(json);
}

TEST(CliDive, ReconstructUsesTheCalibrationItIsGiven) {
  const std::filesystem::path log = TempPath("calibrated.db");
  ASSERT_EQ(RunUwscan("simulate " + SourcePath("data/scenes/default.yaml") + " -o " + log.string())
                .exit_code,
            0);
  const auto mean_error = [&](const std::string& calibration) {
    const std::filesystem::path json = TempPath("calibrated.json");
    const CommandRun run =
        RunUwscan("reconstruct " + log.string() + " -o " + TempPath("c.ply").string() +
                  " --method ray --calibration " + calibration + " --json " + json.string());
    EXPECT_EQ(run.exit_code, 0) << run.output;
    const double mean = ReadJson(json)["truth_error"]["mean_m"].get<double>();
    std::filesystem::remove(json);
    return mean;
  };
  // The true scanner file reproduces the log's own result; the CAD one (mm and degrees off)
  // visibly does not.
  EXPECT_LT(mean_error(SourcePath("data/scanners/galvo_default.yaml")), 1e-6);
  EXPECT_GT(mean_error(SourcePath("data/scanners/galvo_cad.yaml")), 1e-4);
  std::filesystem::remove(log);
  std::filesystem::remove(TempPath("c.ply"));
}

TEST(CliDive, ImportIntrinsicsFromOpenCv) {
  const std::filesystem::path ocv = TempPath("opencv.yaml");
  std::ofstream(ocv)
      << "%YAML:1.0\n---\nimage_width: 2048\nimage_height: 1088\n"
         "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
         "   data: [ 1700.5, 0., 1020.25, 0., 1701.5, 540.75, 0., 0., 1. ]\n"
         "distortion_coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n   dt: d\n"
         "   data: [ -0.1, 0.05, 0.001, -0.002, 0.01 ]\n";
  const std::filesystem::path out = TempPath("imported.yaml");
  const CommandRun run =
      RunUwscan("import-intrinsics " + ocv.string() + " --into " +
                SourcePath("data/scanners/galvo_default.yaml") + " -o " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream in(out);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("fx_px: 1700.5"), std::string::npos) << text;
  EXPECT_NE(text.find("intrinsics:"), std::string::npos) << text;
  // Intrinsics of another image size (a binned camera) are refused; so is writing over an input.
  std::ofstream(ocv)
      << "%YAML:1.0\n---\nimage_width: 1024\nimage_height: 544\n"
         "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
         "   data: [ 850.25, 0., 510.125, 0., 850.75, 270.375, 0., 0., 1. ]\n"
         "distortion_coefficients: !!opencv-matrix\n   rows: 5\n   cols: 1\n   dt: d\n"
         "   data: [ -0.1, 0.05, 0.001, -0.002, 0.01 ]\n";
  const CommandRun binned =
      RunUwscan("import-intrinsics " + ocv.string() + " --into " +
                SourcePath("data/scanners/galvo_default.yaml") + " -o " + out.string());
  EXPECT_EQ(binned.exit_code, 1) << binned.output;
  EXPECT_NE(binned.output.find("calibrated on 1024x544 images, the camera of"), std::string::npos)
      << binned.output;
  const CommandRun over =
      RunUwscan("import-intrinsics " + ocv.string() + " --into " +
                SourcePath("data/scanners/galvo_default.yaml") + " -o " + ocv.string());
  EXPECT_NE(over.output.find("is also an input"), std::string::npos) << over.output;
  std::ofstream(ocv) << "%YAML:1.0\n---\nimage_width: 2048\n";
  const CommandRun bad =
      RunUwscan("import-intrinsics " + ocv.string() + " --into " +
                SourcePath("data/scanners/galvo_default.yaml") + " -o " + out.string());
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_NE(bad.output.find("missing node"), std::string::npos) << bad.output;
  std::filesystem::remove(ocv);
  std::filesystem::remove(out);
}

TEST(CliDive, ForceReplacesOnlyWhatItShouldAndOnlyAfterChecking) {
  // A log is not removed when the new scene fails to load.
  const std::filesystem::path log = TempPath("keep.db");
  std::ofstream(log) << "precious";
  const std::filesystem::path bad = TempPath("bad_scene.yaml");
  std::ofstream(bad) << "uwscan_format: 1\nscanner: {file: /nonexistent.yaml}\nobjects: []\n";
  const CommandRun run = RunUwscan("simulate " + bad.string() + " -o " + log.string() + " --force");
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_EQ(std::filesystem::file_size(log), 8u);
  // --force never replaces a folder that is not a calibration dataset.
  const std::filesystem::path folder = TempPath("not_a_dataset");
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "notes.txt") << "keep me";
  const CommandRun dataset =
      RunUwscan("simulate " + SourcePath("data/scenes/calib_intrinsics.yaml") + " -o " +
                folder.string() + " --force");
  EXPECT_EQ(dataset.exit_code, 1) << dataset.output;
  EXPECT_TRUE(std::filesystem::exists(folder / "notes.txt"));
  std::filesystem::remove_all(folder);
  std::filesystem::remove(log);
  std::filesystem::remove(bad);
}

}  // namespace

namespace {

std::string ReadText(const std::filesystem::path& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A short dive mapped, and the scene's design model beside it: what `uwscan compare` takes.
struct MappedDive {
  std::filesystem::path log = TempPath("compare.db"), design = TempPath("design.ply"),
                        map = TempPath("compare_map.ply"), report = TempPath("compare_map.json");
};

MappedDive MapShortDive() {
  MappedDive d;
  const CommandRun simulated =
      RunUwscan("simulate " + SourcePath("data/scenes/inspection_short.yaml") + " -o " +
                d.log.string() + " --force --design " + d.design.string());
  EXPECT_EQ(simulated.exit_code, 0) << simulated.output;
  const CommandRun mapped =
      RunUwscan("map " + d.log.string() + " -o " + d.map.string() + " --json " + d.report.string());
  EXPECT_EQ(mapped.exit_code, 0) << mapped.output;
  return d;
}

}  // namespace

// compare end to end: the map report against the scene as built writes the deviations PLY with
// the fields CloudCompare reads, the report and the table; bad input gets one line and no file.
TEST(CliDive, CompareWritesDeviationsReportAndTableAndRefusesBadInputWithOneLine) {
  const MappedDive d = MapShortDive();
  const std::filesystem::path ply = TempPath("deviations.ply"), json = TempPath("findings.json"),
                              md = TempPath("findings.md");
  const CommandRun run =
      RunUwscan("compare " + d.report.string() + " --reference " + d.design.string() + " -o " +
                ply.string() + " --json " + json.string() + " --markdown " + md.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::ifstream in(ply, std::ios::binary);
  std::string header, line;
  while (std::getline(in, line) && line != "end_header") header += line + "\n";
  for (const char* field : {"deviation_m", "lod_m", "significant", "inspected", "region"})
    EXPECT_NE(header.find(std::string(" ") + field + "\n"), std::string::npos) << header;
  const nlohmann::json report = ReadJson(json);
  EXPECT_EQ(report["kind"], "change_report");
  EXPECT_EQ(report["reference"]["kind"], "design");
  EXPECT_GT(report["surface"]["unchanged_m2"].get<double>(), 1.0);  // the swath, unchanged
  EXPECT_TRUE(report["alignment"]["registered"].get<bool>());
  EXPECT_NE(ReadText(md).find("| region | kind |"), std::string::npos);
  // The map report carries the graph's information (one pose per SLAM pose), and compare takes
  // how loosely the map placed each point against its tile from it.
  const nlohmann::json map_report = ReadJson(d.report);
  EXPECT_EQ(map_report["pose_graph_information"]["pose_columns"].size(),
            map_report["trajectories"]["slam"].size());
  EXPECT_TRUE(report["settings"]["joint_pose_uncertainty_used"].get<bool>());

  // The dive log itself, mapped by compare as `map` maps it, gives the findings its report gives
  // (to the float rounding of the map file).
  const std::filesystem::path from_log = TempPath("findings_from_log.json");
  const CommandRun logged =
      RunUwscan("compare " + d.log.string() + " --reference " + d.design.string() + " -o " +
                TempPath("deviations_from_log.ply").string() + " --json " + from_log.string());
  ASSERT_EQ(logged.exit_code, 0) << logged.output;
  const nlohmann::json log_report = ReadJson(from_log);
  EXPECT_EQ(log_report["map"]["kind"], "map");
  // The report's map is read back from its PLY, in float, the log's is mapped in memory: a core
  // point at its level of detection may go either way, so the two agree to a few points.
  const double unchanged_m2 = report["surface"]["unchanged_m2"].get<double>();
  EXPECT_NEAR(log_report["surface"]["unchanged_m2"].get<double>(), unchanged_m2,
              1e-3 * unchanged_m2);
  EXPECT_NEAR(static_cast<double>(log_report["regions"].size()),
              static_cast<double>(report["regions"].size()), 2.0);
  EXPECT_TRUE(log_report["settings"]["joint_pose_uncertainty_used"].get<bool>());

  // A design model in millimetres read as metres, an empty map: one line each, nothing written.
  std::filesystem::remove(ply);
  const CommandRun mm = RunUwscan("compare " + d.report.string() + " --reference " +
                                  d.design.string() + " --reference-units mm -o " + ply.string());
  EXPECT_EQ(mm.exit_code, 1) << mm.output;
  EXPECT_NE(mm.output.find("does not overlap"), std::string::npos) << mm.output;
  EXPECT_EQ(std::count(mm.output.begin(), mm.output.end(), '\n'), 1) << mm.output;
  EXPECT_FALSE(std::filesystem::exists(ply));
  const std::filesystem::path empty = TempPath("empty.xyz");
  std::ofstream(empty) << "# nothing\n";
  const CommandRun none = RunUwscan("compare " + empty.string() + " --reference " +
                                    d.design.string() + " -o " + ply.string());
  EXPECT_EQ(none.exit_code, 1) << none.output;
  EXPECT_EQ(std::count(none.output.begin(), none.output.end(), '\n'), 1) << none.output;
  EXPECT_FALSE(std::filesystem::exists(ply));
  for (const auto& p : {d.log, d.design, d.map, d.report, json, md, empty, from_log,
                        TempPath("deviations_from_log.ply")})
    std::filesystem::remove(p);
}
