// The viewer's commands end to end: view --screenshot, --follow, map reports, plot, and the
// one-line error without a display. CTest runs this under Xvfb (cmake/run_with_display.sh).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>

#include "tests/cli_run.hpp"

namespace {

namespace fs = std::filesystem;
using uwscan::test::CommandRun;
using uwscan::test::RunCommand;
using uwscan::test::RunUwscan;

fs::path TempPath(const std::string& name) { return uwscan::test::ScratchPath(name); }

std::string SourcePath(const std::string& relative) {
  return std::string(UWSCAN_SOURCE_DIR) + "/" + relative;
}

std::string Bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A PNG's width and height from its IHDR chunk.
std::pair<int, int> PngSize(const fs::path& path) {
  const std::string b = Bytes(path);
  if (b.size() < 24 || b.compare(1, 3, "PNG") != 0) return {0, 0};
  auto be32 = [&b](std::size_t at) {
    return (int(static_cast<unsigned char>(b[at])) << 24) |
           (int(static_cast<unsigned char>(b[at + 1])) << 16) |
           (int(static_cast<unsigned char>(b[at + 2])) << 8) |
           int(static_cast<unsigned char>(b[at + 3]));
  };
  return {be32(16), be32(20)};
}

fs::path CubeCloud() {
  const fs::path path = TempPath("cube.xyz");
  std::ofstream out(path);
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) {
      for (int k = 0; k < 6; ++k) out << 0.1 * i << " " << 0.1 * j << " " << 0.1 * k << "\n";
    }
  }
  return path;
}

int CountLines(const std::string& text) {
  int lines = 0;
  for (const char c : text) lines += c == '\n';
  return lines;
}

TEST(CliView, WithoutADisplayEveryRenderingCommandFailsWithOneLine) {
  const fs::path cloud = CubeCloud();
  for (const std::string& args :
       {"view " + cloud.string() + " --screenshot " + TempPath("x.png").string(),
        "view " + cloud.string(), std::string("bench viewer --points 1000"),
        "plot " + SourcePath("viewer/testdata/stripe_bench.json") + " -o " +
            TempPath("p.png").string()}) {
    const CommandRun run = RunCommand("env -u DISPLAY " + std::string(UWSCAN_BIN) + " " + args);
    EXPECT_EQ(run.exit_code, 1) << args << "\n" << run.output;
    EXPECT_EQ(CountLines(run.output), 1) << run.output;
    EXPECT_NE(run.output.find("uwscan: error: no X display"), std::string::npos) << run.output;
  }
  EXPECT_FALSE(fs::exists(TempPath("x.png")));
  // A file that is not there says so first, display or not.
  const CommandRun missing = RunCommand("env -u DISPLAY " + std::string(UWSCAN_BIN) + " view " +
                                        TempPath("no_such_cloud.ply").string());
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_NE(missing.output.find("no_such_cloud.ply: no such file"), std::string::npos)
      << missing.output;
  fs::remove(cloud);
}

TEST(CliView, ScreenshotOfACloudHasTheAskedSizeAndIsTheSameTwice) {
  const fs::path cloud = CubeCloud(), a = TempPath("a.png"), b = TempPath("b.png");
  for (const fs::path& png : {a, b}) {
    const CommandRun run = RunUwscan("view " + cloud.string() + " --screenshot " + png.string() +
                                     " --size 400x300 --camera side --edl --point-size 4");
    ASSERT_EQ(run.exit_code, 0) << run.output;
    EXPECT_NE(run.output.find("216 of 216 points drawn"), std::string::npos) << run.output;
  }
  EXPECT_EQ(PngSize(a), std::make_pair(400, 300));
  EXPECT_EQ(Bytes(a), Bytes(b));
  // A point budget draws every k-th point.
  const CommandRun budget =
      RunUwscan("view " + cloud.string() + " --screenshot " + a.string() + " --max-points 100");
  ASSERT_EQ(budget.exit_code, 0) << budget.output;
  EXPECT_NE(budget.output.find("72 of 216 points drawn"), std::string::npos) << budget.output;
  for (const fs::path& p : {cloud, a, b}) fs::remove(p);
}

TEST(CliView, BadInputGivesOneLineNamingIt) {
  const fs::path unknown = TempPath("notes.doc");
  std::ofstream(unknown) << "x";
  const CommandRun run =
      RunUwscan("view " + unknown.string() + " --screenshot " + TempPath("u.png").string());
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_EQ(CountLines(run.output), 1) << run.output;
  EXPECT_NE(run.output.find(unknown.string()), std::string::npos) << run.output;
  const fs::path cloud = CubeCloud();
  const CommandRun error = RunUwscan("view " + cloud.string() + " --colour error --screenshot " +
                                     TempPath("e.png").string());
  EXPECT_EQ(error.exit_code, 1);
  EXPECT_NE(error.output.find("no ground truth"), std::string::npos) << error.output;
  fs::remove(unknown);
  fs::remove(cloud);
}

// A cloud of a simulated scene, coloured by its distance to the scene's true surfaces: points
// 3 to 9 mm outside a sphere of the scene give a colour range within those distances.
TEST(CliView, ACloudIsColouredByItsDistanceToTheScenesSurfaces) {
  const fs::path scene = TempPath("ball.yaml"), cloud = TempPath("ball.xyz"),
                 png = TempPath("ball.png");
  std::ofstream(scene) << "uwscan_format: 1\nscanner: {file: "
                       << SourcePath("data/scanners/galvo_default.yaml")
                       << "}\nobjects:\n  - {name: ball, shape: sphere, radius_m: 0.2,\n"
                          "     pose: {translation_m: [0, 0, 1], rotation_xyzw: [0, 0, 0, 1]}}\n";
  {
    std::ofstream out(cloud);
    for (int i = 0; i < 100; ++i) {
      const double r = 0.203 + 0.006 * i / 99.0, a = 0.0628 * i;
      out << r * std::cos(a) << " " << r * std::sin(a) << " 1\n";
    }
  }
  const CommandRun run = RunUwscan("view " + cloud.string() + " --scene " + scene.string() +
                                   " --screenshot " + png.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("1 cloud coloured by the distance to its surfaces"), std::string::npos)
      << run.output;
  double lo = 0.0, hi = 0.0;
  const std::size_t at = run.output.find("colour by error (");
  ASSERT_NE(at, std::string::npos) << run.output;
  ASSERT_EQ(std::sscanf(run.output.c_str() + at, "colour by error (%lf .. %lf)", &lo, &hi), 2)
      << run.output;
  EXPECT_GE(lo, 0.0029) << run.output;
  EXPECT_LE(hi, 0.0091) << run.output;
  EXPECT_GT(hi - lo, 0.005) << run.output;
  // Without a scene a plain cloud has no error to show, and says how to give it one.
  const CommandRun bare =
      RunUwscan("view " + cloud.string() + " --colour error --screenshot " + png.string());
  EXPECT_EQ(bare.exit_code, 1);
  EXPECT_NE(bare.output.find("--scene"), std::string::npos) << bare.output;
  for (const fs::path& p : {scene, cloud, png}) fs::remove(p);
}

// A scene alone shows its objects (but a sphere, which has no triangles), and without files or a
// scene the command says what it needs.
TEST(CliView, AScenesObjectsAreDrawnWithoutAnyCloud) {
  const fs::path scene = TempPath("objects.yaml"), png = TempPath("objects.png");
  std::ofstream(scene)
      << "uwscan_format: 1\nscanner: {file: " << SourcePath("data/scanners/galvo_default.yaml")
      << "}\nobjects:\n"
         "  - {name: seabed, shape: plane, size_m: [2, 2],\n"
         "     pose: {translation_m: [0, 0, 1.2], rotation_xyzw: [0, 0, 0, 1]}}\n"
         "  - {name: pipe, shape: pipe, outer_radius_m: 0.1, length_m: 1.0,\n"
         "     pose: {translation_m: [0, 0, 1.0], rotation_xyzw: [0, 0.7071068, 0, 0.7071068]}}\n"
         "  - {name: ball, shape: sphere, radius_m: 0.1,\n"
         "     pose: {translation_m: [0.5, 0, 1], rotation_xyzw: [0, 0, 0, 1]}}\n";
  const CommandRun run = RunUwscan("view --scene " + scene.string() + " --screenshot " +
                                   png.string() + " --size 320x240");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("2 objects drawn (1 sphere not drawn)"), std::string::npos)
      << run.output;
  EXPECT_EQ(PngSize(png), std::make_pair(320, 240));
  const CommandRun nothing = RunUwscan("view --screenshot " + png.string());
  EXPECT_EQ(nothing.exit_code, 2) << nothing.output;
  EXPECT_NE(nothing.output.find("--scene"), std::string::npos) << nothing.output;
  for (const fs::path& p : {scene, png}) fs::remove(p);
}

// A hand-made map report in the format `uwscan map --json` writes: its map, three trajectories
// and uncertainty ellipsoids.
TEST(CliView, MapReportIsDrawnWithItsMapTrajectoriesAndEllipsoids) {
  const fs::path dir = TempPath("map");
  fs::create_directories(dir);
  fs::copy_file(CubeCloud(), dir / "map.xyz", fs::copy_options::overwrite_existing);
  std::ostringstream slam, dead, covariance;
  for (int i = 0; i < 20; ++i) {
    const char* comma = i ? "," : "";
    slam << comma << "[" << i << "," << 0.03 * i << ",0.25,-1,0,0,0,1]";
    dead << comma << "[" << i << "," << 0.03 * i << "," << 0.25 + 0.01 * i << ",-1,0,0,0,1]";
    covariance << comma << "[" << i;
    for (int k = 0; k < 36; ++k) covariance << "," << (k % 7 == 0 ? 1e-4 * (i + 1) : 0.0);
    covariance << "]";
  }
  const fs::path report = dir / "report.json";
  std::ofstream(report)
      << R"({"uwscan_format": 1, "kind": "map_report", "log": "dive.db", "map": "map.xyz",
    "trajectories": {"slam": [)"
      << slam.str() << R"(], "dead_reckoning": [)" << dead.str() << R"(]},
    "pose_covariance": [)"
      << covariance.str() << R"(],
    "loops": [{"from_submap": 0, "to_submap": 3, "accepted": true, "reason": "ok"}]})";
  const fs::path png = dir / "map.png";
  const CommandRun run = RunUwscan("view " + report.string() + " --screenshot " + png.string() +
                                   " --ellipsoid-every 5");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_TRUE(fs::exists(png));
  // A broken report names the field.
  std::ofstream(dir / "bad.json")
      << R"({"uwscan_format": 1, "kind": "map_report", "trajectories": {"slam": [[0, 1, 2]]}})";
  const CommandRun bad =
      RunUwscan("view " + (dir / "bad.json").string() + " --screenshot " + png.string());
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.output.find("trajectories.slam[0]"), std::string::npos) << bad.output;
  fs::remove_all(dir);
}

// The recognition pipeline end to end: the demo scene simulated, a database built, `recognize
// --json` on the dive log, and its report drawn: the scan coloured by object with the models,
// labels and grasp frames of what was recognised (whatever that is: this checks the report's
// path from recognize to the viewer, not recognition).
TEST(CliView, RecognitionReportOfTheDemoSceneIsDrawn) {
  const fs::path dir = TempPath("recognition");
  fs::create_directories(dir / "reports");
  const fs::path log = dir / "demo.db", db = dir / "objects.db",
                 report = dir / "reports" / "r.json";
  ASSERT_EQ(RunUwscan("simulate " + SourcePath("data/scenes/default.yaml") + " -o " + log.string())
                .exit_code,
            0);
  const CommandRun build = RunUwscan("build-db valve_wheel flange --views 8 -o " + db.string());
  ASSERT_EQ(build.exit_code, 0) << build.output;
  const CommandRun recognise = RunUwscan("recognize " + log.string() + " --db " + db.string() +
                                         " --json " + report.string());
  ASSERT_EQ(recognise.exit_code, 0) << recognise.output;
  const std::string json = Bytes(report);
  EXPECT_NE(json.find(R"("kind": "recognition_report")"), std::string::npos);
  EXPECT_NE(json.find(R"("scan": "../demo.db")"), std::string::npos)
      << "paths are relative to the report";
  if (json.find(R"("T_S_O")") !=
      std::string::npos) {  // a recognised object lists what fits as well
    EXPECT_NE(json.find(R"("equivalent_objects")"), std::string::npos);
    EXPECT_NE(json.find(R"("equivalent_poses")"), std::string::npos);
  }

  // Drawn from another working directory: the report finds its scan and database.
  const fs::path png = dir / "r.png";
  const CommandRun view =
      RunCommand("cd / && " + std::string(UWSCAN_BIN) + " view " + report.string() +
                 " --screenshot " + png.string() + " --size 640x480");
  ASSERT_EQ(view.exit_code, 0) << view.output;
  EXPECT_NE(view.output.find("colour by object"), std::string::npos) << view.output;
  EXPECT_EQ(PngSize(png), std::make_pair(640, 480));

  // A report whose database has gone names it.
  fs::remove(db);
  const CommandRun missing = RunUwscan("view " + report.string() + " --screenshot " + png.string());
  if (json.find(R"("T_S_O")") !=
      std::string::npos) {  // something was recognised: its model is needed
    EXPECT_EQ(missing.exit_code, 1);
    EXPECT_NE(missing.output.find("objects.db"), std::string::npos) << missing.output;
  }
  fs::remove_all(dir);
}

// A scan from another sensor with invalid rows (NaN, as organised clouds mark missing returns):
// the report's segments give rows of the file, never an invalid one, and the viewer reads the
// report back onto the same rows.
TEST(CliView, ARecognitionReportIndexesTheRowsOfItsScanFile) {
  const fs::path dir = TempPath("rows");
  fs::create_directories(dir);
  const fs::path scan = dir / "holes.xyz", db = dir / "objects.db", report = dir / "r.json";
  std::size_t rows = 0;
  {
    std::ofstream out(scan);
    const auto row = [&](double x, double y, double z) {
      if (rows % 7 == 3) out << "nan nan nan\n", ++rows;  // a hole every seventh row
      out << x << ' ' << y << ' ' << z << '\n';
      ++rows;
    };
    for (int i = 0; i < 120; ++i) {
      for (int j = 0; j < 120; ++j) row(-0.3 + 0.005 * i, -0.3 + 0.005 * j, 1.0);  // a seabed
    }
    for (int i = 0; i < 30; ++i) {  // a 15 cm box standing on it, its top and two sides
      for (int j = 0; j < 30; ++j) {
        const double a = -0.075 + 0.005 * i, b = -0.075 + 0.005 * j;
        row(a, b, 0.85);
        row(a, -0.075, 0.85 + 0.005 * j);
        row(-0.075, a, 0.85 + 0.005 * j);
      }
    }
  }
  ASSERT_EQ(RunUwscan("build-db pipe --views 4 -o " + db.string()).exit_code, 0);
  const CommandRun run = RunUwscan("recognize " + scan.string() + " --db " + db.string() +
                                   " --json " + report.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::size_t holes = (rows + 3) / 7;
  EXPECT_NE(run.output.find(std::to_string(holes) + " of the file's " + std::to_string(rows) +
                            " points dropped"),
            std::string::npos)
      << run.output;
  const std::string json = Bytes(report);
  EXPECT_NE(json.find("\"scan_points\": " + std::to_string(rows)), std::string::npos);
  std::size_t listed = 0;
  for (std::size_t at = json.find("\"segment\": ["); at != std::string::npos;
       at = json.find("\"segment\": [", at + 1)) {
    std::istringstream in(json.substr(at + 12, json.find(']', at) - at - 12));
    std::string number;
    while (std::getline(in, number, ',')) {
      const std::size_t row = std::stoul(number);
      EXPECT_LT(row, rows);
      EXPECT_NE(row % 7, 3u) << "row " << row << " is a hole";
      ++listed;
    }
  }
  EXPECT_GT(listed, 1000u) << json.substr(0, 400);
  const fs::path png = dir / "r.png";
  const CommandRun view =
      RunUwscan("view " + report.string() + " --screenshot " + png.string() + " --size 320x240");
  EXPECT_EQ(view.exit_code, 0) << view.output;
  fs::remove_all(dir);
}

// `view --follow` started before the log exists shows every frame `simulate` then writes.
TEST(CliView, FollowPicksUpADiveWrittenAfterItStarted) {
  const fs::path log = TempPath("follow.db"), png = TempPath("follow.png"),
                 out = TempPath("follow.txt");
  fs::remove(log);
  std::thread viewer([&] {
    const CommandRun run = RunUwscan(
        "view " + log.string() +
        " --follow --frames 201 --timeout 120 --colour error --screenshot " + png.string());
    std::ofstream(out) << run.exit_code << "\n" << run.output;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const CommandRun sim =
      RunUwscan("simulate " + SourcePath("data/scenes/default.yaml") + " -o " + log.string());
  viewer.join();
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const std::string result = Bytes(out);
  EXPECT_EQ(result.rfind("0\n", 0), 0u) << result;
  EXPECT_NE(result.find("followed 201 frames, 206699 points"), std::string::npos) << result;
  EXPECT_TRUE(fs::exists(png));
  for (const fs::path& p : {log, png, out}) fs::remove(p);
}

TEST(CliView, PlotDrawsABenchJsonAndRefusesOtherJson) {
  const fs::path png = TempPath("stripe.png");
  const CommandRun run =
      RunUwscan("plot " + SourcePath("viewer/testdata/stripe_bench.json") + " -o " + png.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("stripe bench plotted"), std::string::npos);
  EXPECT_EQ(PngSize(png), std::make_pair(760, 560));
  const fs::path other = TempPath("other.json");
  std::ofstream(other) << R"({"hello": 1})";
  const CommandRun bad = RunUwscan("plot " + other.string() + " -o " + png.string());
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.output.find("not the JSON of a bench"), std::string::npos) << bad.output;
  fs::remove(png);
  fs::remove(other);
}

}  // namespace
