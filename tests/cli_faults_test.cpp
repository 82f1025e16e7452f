// Faults that must lose nothing (issue 14, item 5): outputs that cannot or must not be written
// are refused before any work; a full disk or a read-only folder gives a clear error and leaves
// no half-written file; a command killed at any moment leaves the old output or a complete new
// one. The folder faults run in a private mount namespace (tmpfs mounts of their own), as CI
// does as root; without one the tests fail saying why.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "perception/cloud/cloud_io.hpp"
#include "tests/cli_run.hpp"

namespace uwscan::test {
namespace {

namespace fs = std::filesystem;

std::string Bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string Scene(const char* name) {
  return std::string(UWSCAN_SOURCE_DIR) + "/data/scenes/" + name;
}

class CliFaults : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("uwscan_cli_faults_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    ASSERT_EQ(RunUwscan("simulate " + Scene("default.yaml") + " -o " + (dir_ / "dive.db").string())
                  .exit_code,
              0);
    ASSERT_EQ(RunUwscan("reconstruct " + (dir_ / "dive.db").string() + " -o " +
                        (dir_ / "cloud.ply").string())
                  .exit_code,
              0);
    ASSERT_EQ(RunUwscan("reconstruct " + (dir_ / "dive.db").string() +
                        " --method plane --ascii -o " + (dir_ / "old.ply").string())
                  .exit_code,
              0);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  // A shell command line run in a private mount namespace with a tmpfs at `folder`.
  static CommandRun InTmpfs(const fs::path& folder, const std::string& options,
                            const std::string& commands) {
    fs::create_directories(folder);
    return RunCommand("unshare -m sh -c 'mount -t tmpfs -o " + options + " tmpfs " +
                      folder.string() + " && " + commands + "'");
  }

  static inline fs::path dir_;
};

TEST_F(CliFaults, OutputsThatCannotBeWrittenAreRefusedBeforeAnyWork) {
  const std::string dive = (dir_ / "dive.db").string(), cloud = (dir_ / "cloud.ply").string();
  const std::string missing = (dir_ / "no" / "such" / "folder").string();
  struct Case {
    std::string arguments;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"simulate " + Scene("default.yaml") + " -o " + missing + "/d.db", "does not exist"},
      {"reconstruct " + dive + " -o " + missing + "/c.ply", "does not exist"},
      {"reconstruct " + dive + " -o " + cloud + " --json " + dive, "is also an input"},
      {"reconstruct " + dive + " -o " + dir_.string(), "is a folder"},
      {"register " + cloud + " " + (dir_ / "old.ply").string() + " -o " + cloud,
       "is also an input"},
      {"map " + dive + " -o " + missing + "/m.ply", "does not exist"},
      {"map " + dive + " -o " + (dir_ / "m.ply").string() + " --trajectory " + dive,
       "is also an input"},
      {"build-db pipe -o " + missing + "/o.db", "does not exist"},
      {"acquire --camera 127.0.0.1 -o " + missing + "/a.db --frames 1", "does not exist"},
      {"log salvage " + dive + " -o " + dive, "is also an input"},
      {"view " + dive + " --screenshot " + missing + "/v.png", "does not exist"},
      {"plot " + dive + " -o " + dive, "is also an input"},
      {"recognize " + cloud + " --db " + dive + " --json " + missing + "/r.json", "does not exist"},
      {"reconstruct " + dive + " -o " + (dir_ / "c.xyz").string(),
       "a point cloud is written as .ply or .pcd"},
      {"map " + dive + " -o " + (dir_ / "m.xyz").string(),
       "a point cloud is written as .ply or .pcd"},
      {"register " + cloud + " " + (dir_ / "old.ply").string() + " -o " + (dir_ / "r.txt").string(),
       "a point cloud is written as .ply or .pcd"},
  };
  for (const Case& c : cases) {
    const auto start = std::chrono::steady_clock::now();
    const CommandRun run = RunUwscan(c.arguments);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_NE(run.exit_code, 0) << c.arguments;
    EXPECT_NE(run.output.find(c.expected), std::string::npos) << c.arguments << "\n" << run.output;
    EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << c.arguments << "\n"
                                                                         << run.output;
    // Refused before the work starts (the slowest of these takes tens of seconds when it runs).
    EXPECT_LT(seconds, 5.0) << c.arguments;
  }
  EXPECT_FALSE(fs::exists(dir_ / "m.ply"));
  EXPECT_TRUE(fs::is_regular_file(dive));
}

// A scan read in a unit it is not in is a size no scan has: refused with a hint, in one line.
TEST_F(CliFaults, AScanInAnotherUnitIsRefusedWithAHintAboutUnits) {
  const std::string cloud = (dir_ / "cloud.ply").string(), dive = (dir_ / "dive.db").string();
  const std::string mm = (dir_ / "cloud_mm.xyz").string();
  {
    const perception::PointCloud metres = perception::ReadCloud(cloud);
    std::ofstream out(mm);
    for (std::size_t i = 0; i < metres.size(); ++i) {
      const Eigen::Vector3d p = 1000.0 * metres.Point(i);
      out << p.x() << " " << p.y() << " " << p.z() << "\n";
    }
  }
  struct Case {
    std::string arguments, expected;
  };
  const std::vector<Case> cases = {
      {"recognize " + mm + " --db " + dive, "is it in millimetres? give --units mm"},
      {"recognize " + cloud + " --db " + dive + " --units mm", "is it in metres? give --units m"},
      {"recognize " + cloud + " --db " + dive + " --viewpoint 1 2 3 4",
       "--viewpoint: expected 7 numbers: tx ty tz qx qy qz qw (or 3: tx ty tz)"},
      {"recognize " + dive + " --db " + dive + " --units mm", "a dive log is in metres"},
  };
  for (const Case& c : cases) {
    const CommandRun run = RunUwscan(c.arguments);
    EXPECT_NE(run.exit_code, 0) << c.arguments;
    EXPECT_NE(run.output.find(c.expected), std::string::npos) << c.arguments << "\n" << run.output;
    EXPECT_EQ(std::count(run.output.begin(), run.output.end(), '\n'), 1) << run.output;
  }
}

TEST_F(CliFaults, AReadOnlyFolderIsRefusedBeforeAnyWork) {
  const fs::path folder = dir_ / "read_only";
  const CommandRun run =
      InTmpfs(folder, "ro",
              std::string(UWSCAN_BIN) + " reconstruct " + (dir_ / "dive.db").string() + " -o " +
                  (folder / "c.ply").string());
  ASSERT_EQ(run.output.find("unshare:"), std::string::npos)
      << "no private mount namespace (CI runs as root): " << run.output;
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("is not writable"), std::string::npos) << run.output;
}

TEST_F(CliFaults, AFullDiskGivesAClearErrorAndKeepsTheOldFile) {
  const fs::path folder = dir_ / "full";
  const std::string bin = UWSCAN_BIN;
  // 1 MiB: the old file fits, the new cloud (a few MB) does not, nor does a dive log.
  const std::string commands =
      "printf old-cloud > " + folder.string() + "/c.ply; " + bin + " reconstruct " +
      (dir_ / "dive.db").string() + " -o " + folder.string() + "/c.ply; echo exit=$?; " + bin +
      " simulate " + Scene("default.yaml") + " -o " + folder.string() + "/d.db; echo exit=$?; " +
      "echo files: $(ls -A " + folder.string() + "); [ \"$(cat " + folder.string() +
      "/c.ply)\" = old-cloud ] && echo old-file-intact";
  const CommandRun run = InTmpfs(folder, "size=1m", commands);
  ASSERT_EQ(run.output.find("unshare:"), std::string::npos)
      << "no private mount namespace: " << run.output;
  EXPECT_EQ(run.output.find("exit=0"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("No space left on device"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("old-file-intact"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("files: c.ply\n"), std::string::npos)
      << "a half-written file was left:\n"
      << run.output;
}

// A dive log damaged in its middle: `map` stops at the damaged frame with an error naming it, and
// the stage it was in ends "stopped", not "done"; the old map stays.
TEST_F(CliFaults, AStageAnErrorCutsShortEndsStoppedNotDone) {
  const fs::path damaged = dir_ / "damaged.db", map = dir_ / "damaged_map.ply";
  fs::copy_file(dir_ / "dive.db", damaged, fs::copy_options::overwrite_existing);
  {
    std::fstream file(damaged, std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(static_cast<std::streamoff>(0.6 * static_cast<double>(fs::file_size(damaged))));
    std::mt19937 rng(11);
    for (int i = 0; i < 20000; ++i) file.put(static_cast<char>(rng() & 0xff));
  }
  std::ofstream(map) << "old map";
  const CommandRun run = RunUwscan("map " + damaged.string() + " -o " + map.string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("dive log"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("map: stopped"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("map: done"), std::string::npos) << run.output;
  EXPECT_EQ(Bytes(map), "old map");
}

// The temporary folder long commands spill to, missing: a one-line error naming $TMPDIR (it was
// an "internal error" from the standard library), nothing written.
TEST_F(CliFaults, AMissingTemporaryFolderIsNamed) {
  const fs::path missing = dir_ / "no_such_tmp", map = dir_ / "tmpdir_map.ply";
  std::ofstream(map) << "old map";
  const CommandRun run = RunCommand("env TMPDIR=" + missing.string() + " " + UWSCAN_BIN + " map " +
                                    (dir_ / "dive.db").string() + " -o " + map.string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("$TMPDIR (" + missing.string() + ")"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("internal error"), std::string::npos) << run.output;
  EXPECT_EQ(Bytes(map), "old map");
}

// A file size limit (ulimit -f) under the new map's size: the write fails with a one-line error
// and the old map stays, with no temporary file beside it; without SIGXFSZ ignored the program
// was killed by the signal mid-write, with no error and its temporary file left behind.
TEST_F(CliFaults, AFileSizeLimitIsAClearErrorNotASignal) {
  const fs::path folder = dir_ / "limited";
  fs::create_directories(folder);
  const fs::path map = folder / "map.ply";
  std::ofstream(map) << "old map";
  const CommandRun run = RunCommand("ulimit -f 64; exec " + std::string(UWSCAN_BIN) + " map " +
                                    (dir_ / "dive.db").string() + " -o " + map.string());
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("File too large"), std::string::npos) << run.output;
  EXPECT_EQ(Bytes(map), "old map");
  EXPECT_EQ(std::distance(fs::directory_iterator(folder), fs::directory_iterator()), 1)
      << "a temporary file was left beside the map";
}

// A scene asking for more frames than the output's disk can hold is refused at once, before the
// work (a scene of 10^8 sweeps took 4.7 GB of memory in 8 s and would have filled the disk
// hours later). Here 100 sweeps, 20,100 frames, onto a 1 MB disk.
TEST_F(CliFaults, ADiveTheDiskCannotHoldIsRefusedBeforeAnyWork) {
  std::string scene = Bytes(Scene("default.yaml"));
  const std::string relative = "file: ../scanners/galvo_default.yaml", sweeps = "sweeps: 1\n";
  ASSERT_NE(scene.find(relative), std::string::npos);
  ASSERT_NE(scene.find(sweeps), std::string::npos);
  scene.replace(scene.find(relative), relative.size(),
                "file: " + std::string(UWSCAN_SOURCE_DIR) + "/data/scanners/galvo_default.yaml");
  scene.replace(scene.find(sweeps), sweeps.size(), "sweeps: 100\n");
  const fs::path long_dive = dir_ / "long_dive.yaml", small = dir_ / "small_disk";
  std::ofstream(long_dive) << scene;
  const CommandRun run = InTmpfs(
      small, "size=1m",
      std::string(UWSCAN_BIN) + " simulate " + long_dive.string() + " -o " + small.string() +
          "/d.db; echo exit=$?; echo files: " + "$(ls -A " + small.string() + ")");
  ASSERT_EQ(run.output.find("unshare:"), std::string::npos)
      << "no private mount namespace: " << run.output;
  EXPECT_NE(run.output.find("exit=1"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("20100 frames need at least"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("files:\n"), std::string::npos) << run.output;
}

// One output of a command killed at random moments: what it held before, and what a complete run
// writes (with `normalise` applied: lines that differ between runs, such as timings, dropped).
struct KilledOutput {
  fs::path path;
  std::string old_bytes;
  std::string new_bytes;
};

// A calibration file without the lines of its record that differ between runs (when, how long).
std::string WithoutRunRecord(const std::string& text) {
  std::istringstream lines(text);
  std::string kept, line;
  while (std::getline(lines, line)) {
    if (line.find("seconds:") == std::string::npos && line.find("date_utc:") == std::string::npos)
      kept += line + '\n';
  }
  return kept;
}

pid_t StartShell(const std::string& command) {
  const pid_t child = ::fork();
  if (child == 0) {
    ::execl("/bin/sh", "sh", "-c", ("exec " + command + " >/dev/null 2>&1").c_str(), nullptr);
    ::_exit(127);
  }
  return child;
}

// Runs `command` once to the end (for the complete outputs and its duration), then kills it with
// SIGKILL at random moments, half over the whole run and half over its last fifth, where the
// outputs are written: each output must then be its old bytes or the complete new ones.
void KillAtRandomMoments(const std::string& command, std::vector<KilledOutput> outputs, int trials,
                         std::string (*normalise)(const std::string&) = nullptr) {
  const auto normalised = [normalise](const std::string& bytes) {
    return normalise ? normalise(bytes) : bytes;
  };
  for (const KilledOutput& output : outputs) fs::remove(output.path);
  const auto start = std::chrono::steady_clock::now();
  const CommandRun complete = RunCommand(command);
  const double run_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(complete.exit_code, 0) << command << "\n" << complete.output;
  for (KilledOutput& output : outputs) output.new_bytes = normalised(Bytes(output.path));

  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> anywhere(0.0, run_s),
      near_the_end(0.8 * run_s, 1.05 * run_s);
  for (int trial = 0; trial < trials; ++trial) {
    for (const KilledOutput& output : outputs)
      std::ofstream(output.path, std::ios::binary) << output.old_bytes;
    const double moment_s = trial % 2 == 0 ? anywhere(rng) : near_the_end(rng);
    const pid_t child = StartShell(command);
    ASSERT_GE(child, 0);
    std::this_thread::sleep_for(std::chrono::duration<double>(moment_s));
    ::kill(child, SIGKILL);
    ::waitpid(child, nullptr, 0);
    for (const KilledOutput& output : outputs) {
      const std::string now = Bytes(output.path);
      EXPECT_TRUE(now == output.old_bytes || normalised(now) == output.new_bytes)
          << command << ": killed after " << moment_s << " s (of " << run_s << "), " << output.path
          << " holds " << now.size() << " bytes (old " << output.old_bytes.size() << ", new "
          << output.new_bytes.size() << ")";
    }
  }
}

TEST_F(CliFaults, KilledAtAnyMomentTheOutputIsTheOldFileOrACompleteNewOne) {
  const std::string old_bytes = Bytes(dir_ / "old.ply");
  const std::string bin = UWSCAN_BIN, dive = (dir_ / "dive.db").string();
  const fs::path cloud = dir_ / "killed.ply";
  KillAtRandomMoments(bin + " reconstruct " + dive + " -o " + cloud.string(),
                      {{cloud, old_bytes, ""}}, 8);

  const fs::path registered = dir_ / "registered.ply";
  KillAtRandomMoments(bin + " register " + (dir_ / "cloud.ply").string() + " " +
                          (dir_ / "old.ply").string() + " -o " + registered.string(),
                      {{registered, old_bytes, ""}}, 8);

  // The mapper's spill files (old clouds and measurements) go to TMPDIR: a killed mapper must
  // leave none there (mapping/slam/spill_file.hpp).
  const fs::path map = dir_ / "map.ply", trajectory = dir_ / "slam.tum", spill = dir_ / "spill";
  fs::create_directories(spill);
  KillAtRandomMoments("env TMPDIR=" + spill.string() + " " + bin + " map " + dive + " -o " +
                          map.string() + " --trajectory " + trajectory.string(),
                      {{map, old_bytes, ""}, {trajectory, "0 0 0 0 0 0 0 1\n", ""}}, 8);
  EXPECT_TRUE(fs::is_empty(spill)) << fs::directory_iterator(spill)->path();

  const fs::path database = dir_ / "objects.db";
  KillAtRandomMoments(bin + " build-db pipe -o " + database.string(),
                      {{database, "old database", ""}}, 6);

  // calibrate on a small simulated intrinsics dataset; its record holds the run's date and
  // duration.
  const fs::path scene = dir_ / "calibration.yaml", dataset = dir_ / "calibration_dataset";
  std::ofstream(scene)
      << "uwscan_format: 1\nseed: 5\nwater: {refractive_index: 1.0}\nscanner:\n  file: "
      << UWSCAN_SOURCE_DIR << "/data/scanners/galvo_default.yaml\neffects:\n  refraction: false\n"
      << "  image: {format: mono8}\ncalibration:\n  step: intrinsics\n  pattern: {type: "
         "chessboard, "
      << "columns: 9, rows: 6, square_m: 0.03}\n  views: 6\n  distance_m: [0.5, 0.8]\n"
      << "  max_tilt_rad: 0.5\n  image_scale: 0.5\n";
  ASSERT_EQ(RunUwscan("simulate " + scene.string() + " -o " + dataset.string()).exit_code, 0);
  const fs::path calibration = dir_ / "calibrated.yaml";
  KillAtRandomMoments(bin + " calibrate intrinsics " + dataset.string() + " -o " +
                          calibration.string() + " --from " + UWSCAN_SOURCE_DIR +
                          "/data/scanners/galvo_default.yaml",
                      {{calibration, "old: calibration\n", ""}}, 8, WithoutRunRecord);

  // simulate --force over an older log: the output stays a readable log, old or new.
  const fs::path log = dir_ / "killed.db";
  const std::string old_log = Bytes(dir_ / "dive.db");
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 5; ++trial) {
    { std::ofstream(log, std::ios::binary) << old_log; }
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::execl(UWSCAN_BIN, UWSCAN_BIN, "simulate", Scene("default.yaml").c_str(), "-o", log.c_str(),
              "--force", nullptr);
      ::_exit(127);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100 + rng() % 1200));
    ::kill(child, SIGKILL);
    ::waitpid(child, nullptr, 0);
    const CommandRun check = RunUwscan("log check " + log.string());
    EXPECT_EQ(check.exit_code, 0) << check.output;
  }
}

}  // namespace
}  // namespace uwscan::test
