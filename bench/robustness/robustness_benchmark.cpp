#include "bench/robustness/robustness_benchmark.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <random>
#include <regex>
#include <vector>

#include "bench/robustness/reader_probes.hpp"
#include "bench/robustness/reader_seeds.hpp"
#include "mapping/log/dive_log.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/common/random_draws.hpp"
#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::bench {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

enum class Mutation { kTruncated, kBytesFlipped, kCountsInflated, kNanInf, kWrongTypes };
constexpr std::array kMutations = {Mutation::kTruncated, Mutation::kBytesFlipped,
                                   Mutation::kCountsInflated, Mutation::kNanInf,
                                   Mutation::kWrongTypes};

const char* ToString(Mutation m) {
  switch (m) {
    case Mutation::kTruncated:
      return "truncated";
    case Mutation::kBytesFlipped:
      return "bytes flipped";
    case Mutation::kCountsInflated:
      return "count inflated";
    case Mutation::kNanInf:
      return "NaN/Inf injected";
    case Mutation::kWrongTypes:
      return "wrong type";
  }
  return "?";
}

void WriteBytes(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out.flush()) throw Error("cannot write '" + path.string() + "'");
}

bool IsText(const std::string& bytes) { return bytes.find('\0') == std::string::npos; }

// Replaces one number of a text file (picked at random) with `replacement`; false when the text
// holds no number.
bool ReplaceNumber(std::string& text, const std::string& replacement, std::mt19937_64& rng) {
  static const std::regex number(R"([-+]?[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?)");
  std::vector<std::pair<std::size_t, std::size_t>> spans;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), number);
       it != std::sregex_iterator(); ++it) {
    spans.emplace_back(static_cast<std::size_t>(it->position()),
                       static_cast<std::size_t>(it->length()));
  }
  if (spans.empty()) return false;
  const auto [at, length] = spans[rng() % spans.size()];
  text.replace(at, length, replacement);
  return true;
}

// Writes the bytes of `value` at a random offset aligned to its size.
template <typename T>
void Overwrite(std::string& bytes, T value, std::mt19937_64& rng) {
  if (bytes.size() < sizeof(T)) return;
  const std::size_t slots = bytes.size() / sizeof(T);
  std::memcpy(bytes.data() + (rng() % slots) * sizeof(T), &value, sizeof(T));
}

template <std::size_t N>
const char* Pick(const std::array<const char*, N>& choices, std::mt19937_64& rng) {
  return choices[rng() % N];
}

std::string Mutate(const std::string& seed, Mutation mutation, std::mt19937_64& rng) {
  std::string bytes = seed;
  const bool text = IsText(seed);
  switch (mutation) {
    case Mutation::kTruncated:
      bytes.resize(bytes.empty() ? 0 : rng() % bytes.size());
      break;
    case Mutation::kBytesFlipped: {
      const int count = 1 + static_cast<int>(rng() % 16);
      for (int k = 0; k < count && !bytes.empty(); ++k)
        bytes[rng() % bytes.size()] = static_cast<char>(rng());
      break;
    }
    case Mutation::kCountsInflated:
      if (text) {
        ReplaceNumber(bytes,
                      Pick(std::array{"4294967295", "2147483648", "99999999999999999999", "-1", "0",
                                      "1000000000"},
                           rng),
                      rng);
      } else if (rng() % 2) {
        Overwrite<std::uint32_t>(bytes, rng() % 2 ? 0xFFFFFFFFu : 0x7FFFFFFFu, rng);
      } else {
        Overwrite<std::uint64_t>(bytes, 0xFFFFFFFFFFFFull << (rng() % 16), rng);
      }
      break;
    case Mutation::kNanInf:
      if (text) {
        ReplaceNumber(
            bytes,
            Pick(std::array{"nan", ".nan", "NaN", "inf", "-inf", ".inf", "1e999", "-1e999"}, rng),
            rng);
      } else if (rng() % 2) {
        Overwrite<float>(bytes,
                         rng() % 2 ? std::numeric_limits<float>::quiet_NaN()
                                   : std::numeric_limits<float>::infinity(),
                         rng);
      } else {
        Overwrite<double>(bytes,
                          rng() % 2 ? std::numeric_limits<double>::quiet_NaN()
                                    : -std::numeric_limits<double>::infinity(),
                          rng);
      }
      break;
    case Mutation::kWrongTypes:
      if (text) {
        ReplaceNumber(
            bytes,
            Pick(std::array{"abc", "[1, 2]", "{a: 1}", "true", "\"7\"", "~", "null", "[]"}, rng),
            rng);
      } else if (!bytes.empty()) {
        const std::string word = "uwscan";
        const std::size_t at = rng() % bytes.size();
        bytes.replace(at, std::min(word.size(), bytes.size() - at),
                      word.substr(0, bytes.size() - at));
      }
      break;
  }
  return bytes;
}

enum class Outcome { kAccepted, kCleanError, kCrash, kHang };
constexpr int kExitAccepted = 0;
constexpr int kExitCleanError = 10;
constexpr int kExitOtherException = 20;

struct ChildResult {
  Outcome outcome = Outcome::kCrash;
  bool printed = false;
};

// Runs `read` in a child process with its stdout and stderr captured; the parent has no other
// thread (fork copies only the caller).
ChildResult ReadInChild(const std::function<void()>& read, double timeout_s) {
  int output[2];
  if (::pipe(output) != 0) throw Error("bench robustness: cannot create a pipe");
  const pid_t child = ::fork();
  if (child < 0) throw Error("bench robustness: cannot fork");
  if (child == 0) {
    ::close(output[0]);
    ::dup2(output[1], STDOUT_FILENO);
    ::dup2(output[1], STDERR_FILENO);
    int code = kExitAccepted;
    try {
      read();
    } catch (const Error&) {
      code = kExitCleanError;
    } catch (...) {
      code = kExitOtherException;
    }
    ::_exit(code);
  }
  ::close(output[1]);
  ChildResult result;
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s);
  int status = 0;
  bool done = false;
  while (!done) {
    pollfd fd{output[0], POLLIN, 0};
    if (::poll(&fd, 1, 20) > 0) {
      char buffer[256];
      const ssize_t n = ::read(output[0], buffer, sizeof(buffer));
      if (n > 0) result.printed = true;
    }
    const pid_t waited = ::waitpid(child, &status, WNOHANG);
    if (waited == child) {
      done = true;
    } else if (Clock::now() > deadline) {
      ::kill(child, SIGKILL);
      ::waitpid(child, &status, 0);
      ::close(output[0]);
      result.outcome = Outcome::kHang;
      return result;
    }
  }
  char buffer[256];
  while (::read(output[0], buffer, sizeof(buffer)) > 0) result.printed = true;
  ::close(output[0]);
  if (WIFEXITED(status) && WEXITSTATUS(status) == kExitAccepted)
    result.outcome = Outcome::kAccepted;
  if (WIFEXITED(status) && WEXITSTATUS(status) == kExitCleanError)
    result.outcome = Outcome::kCleanError;
  return result;
}

void Count(ReaderOutcomes& outcomes, const ChildResult& result, const std::string& what) {
  ++outcomes.tried;
  if (result.printed) ++outcomes.noisy;
  switch (result.outcome) {
    case Outcome::kAccepted:
      ++outcomes.accepted;
      break;
    case Outcome::kCleanError:
      ++outcomes.clean_error;
      break;
    case Outcome::kCrash:
      ++outcomes.crash;
      break;
    case Outcome::kHang:
      ++outcomes.hang;
      break;
  }
  const bool failure = result.outcome == Outcome::kCrash || result.outcome == Outcome::kHang;
  if (failure && outcomes.first_failure.empty()) outcomes.first_failure = what;
}

ReaderOutcomes MeasureReader(const ReaderProbe& probe, const std::vector<fs::path>& seeds,
                             const fs::path& workspace, const RobustnessOptions& options,
                             std::mt19937_64& rng) {
  ReaderOutcomes outcomes;
  const fs::path input = ReaderInputPath(probe, workspace);
  for (const fs::path& seed_path : seeds) {
    const std::string seed = ReadFileBytes(seed_path);
    for (Mutation mutation : kMutations) {
      for (int k = 0; k < options.mutants_per_kind; ++k) {
        WriteBytes(input, Mutate(seed, mutation, rng));
        const ChildResult result = ReadInChild([&] { probe.read(input); }, options.timeout_s);
        Count(outcomes, result,
              seed_path.filename().string() + ", " + ToString(mutation) + " #" + std::to_string(k));
      }
    }
  }
  return outcomes;
}

// ---- Dive logs: random bytes changed in a whole file ----

struct OriginalLog {
  std::vector<mapping::FrameRecord> frames;
  std::vector<mapping::GroundTruthRecord> truths;
  std::vector<mapping::NavigationRecord> navigation;
};

constexpr double kNavigationStep_s = 0.003;

OriginalLog WriteOriginalLog(const fs::path& path) {
  mapping::DiveLogHeader header;
  header.scanner = scanner::DefaultScanner(scanner::ScannerKind::kGalvo);
  header.scan_pattern.kind = scanner::ScannerKind::kGalvo;
  header.producer = "uwscan bench robustness";
  OriginalLog log;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 2000.0);
  mapping::DiveLogWriter writer(path, header);
  for (int i = 0; i < 300; ++i) {
    mapping::FrameRecord frame;
    frame.index = i;
    frame.time_s = 0.003 * i;
    frame.command = i % 100;
    frame.sweep = i / 100;
    mapping::GroundTruthRecord truth;
    for (int k = 0; k < 150; ++k) {
      frame.peaks_px.push_back(DrawVector2LastFirst(u, rng));
      const Eigen::Vector2d xy = 1e-3 * DrawVector2LastFirst(u, rng);
      truth.points_W.emplace_back(xy.x(), xy.y(), 1.0);
      truth.object_ids.push_back(k % 3);
    }
    writer.AppendFrame(frame, &truth);
    const mapping::NavigationRecord nav{
        kNavigationStep_s * i, Eigen::Isometry3d(Eigen::Translation3d(0.001 * i, 0.0, 5.0))};
    writer.AppendNavigation(nav);
    log.frames.push_back(std::move(frame));
    log.truths.push_back(std::move(truth));
    log.navigation.push_back(nav);
  }
  return log;
}

bool SameFrame(const mapping::FrameRecord& a, const mapping::FrameRecord& b) {
  return a.time_s == b.time_s && a.command == b.command && a.sweep == b.sweep &&
         a.peaks_px == b.peaks_px && a.image.has_value() == b.image.has_value();
}

bool SameTruth(const mapping::GroundTruthRecord* a, const mapping::GroundTruthRecord& b) {
  return a != nullptr && a->points_W == b.points_W && a->object_ids == b.object_ids &&
         a->T_W_C.isApprox(b.T_W_C, 1e-12);
}

// A copy of a version 3 log as a version 2 writer would have made it: no checksums.
void StripChecksums(const fs::path& path) {
  sqlite3* db = nullptr;
  if (sqlite3_open(path.c_str(), &db) != SQLITE_OK)
    throw Error("cannot open '" + path.string() + "'");
  const char* sql =
      "ALTER TABLE header DROP COLUMN checksums; ALTER TABLE frames DROP COLUMN checksums;"
      "ALTER TABLE ground_truth DROP COLUMN checksums; ALTER TABLE navigation DROP COLUMN "
      "checksums;"
      "UPDATE meta SET value = 2 WHERE key = 'schema_version'; VACUUM;";
  const int rc = sqlite3_exec(db, sql, nullptr, nullptr, nullptr);
  sqlite3_close(db);
  if (rc != SQLITE_OK) throw Error("cannot strip the checksums of '" + path.string() + "'");
}

// Changes `count` bytes at random places of a copy of `original`.
void DamageCopy(const fs::path& original, const fs::path& copy, int count, std::mt19937_64& rng) {
  std::string bytes = ReadFileBytes(original);
  for (int k = 0; k < count; ++k) bytes[rng() % bytes.size()] = static_cast<char>(rng());
  WriteBytes(copy, bytes);
}

// Damaged rows: every original row the damaged log does not give back as it was; detected: those
// it refuses (flagged, missing, or the whole file refused) rather than hands over changed.
DiveLogDamage CountDamage(const fs::path& damaged, const OriginalLog& original, double timeout_s) {
  int report[2];
  if (::pipe(report) != 0) throw Error("bench robustness: cannot create a pipe");
  const ChildResult result = ReadInChild(
      [&] {
        DiveLogDamage damage;
        // Rows: frames, their ground truth, navigation samples. A frame handed over without its
        // truth had its truth row flagged as damaged (DiveLogReader::Check): detected, not
        // silent (every frame of the original has its truth).
        int frames_back = 0, truths_back = 0, navigation_back = 0, silent = 0;
        try {
          const mapping::DiveLogReader reader(damaged);
          reader.Check(
              [&](const mapping::FrameRecord& frame, const mapping::GroundTruthRecord* truth) {
                ++frames_back;
                const std::size_t i = static_cast<std::size_t>(frame.index);
                const bool known = i < original.frames.size();
                if (!known || !SameFrame(frame, original.frames[i])) ++silent;
                if (truth == nullptr) return;  // its truth row flagged
                ++truths_back;
                if (!known || !SameTruth(truth, original.truths[i])) ++silent;
              },
              [&](const mapping::NavigationRecord& nav) {
                ++navigation_back;
                // Sample i was written at time kNavigationStep_s * i: a changed time is damage too.
                const double slot = std::round(nav.time_s / kNavigationStep_s);
                const bool in_range = slot >= 0.0 && slot < double(original.navigation.size());
                const std::size_t i = in_range ? static_cast<std::size_t>(slot) : 0;
                const bool same = in_range && nav.time_s == original.navigation[i].time_s &&
                                  nav.T_W_V.isApprox(original.navigation[i].T_W_V, 1e-12);
                if (!same) ++silent;
              });
        } catch (const Error&) {
          // Refused as a whole: nothing handed over.
        }
        const int rows = static_cast<int>(original.frames.size() + original.truths.size() +
                                          original.navigation.size());
        const int refused = rows - frames_back - truths_back - navigation_back;
        damage.damaged_rows = refused + silent;
        damage.detected = refused;
        if (::write(report[1], &damage, sizeof(damage)) != sizeof(damage))
          ::_exit(kExitOtherException);
      },
      timeout_s);
  ::close(report[1]);
  DiveLogDamage damage;
  const bool reported = ::read(report[0], &damage, sizeof(damage)) == sizeof(damage);
  ::close(report[0]);
  if (result.outcome != Outcome::kAccepted || !reported) {
    throw Error("bench robustness: checking a damaged dive log " +
                std::string(result.outcome == Outcome::kHang ? "hung" : "crashed") + " ('" +
                damaged.string() + "')");
  }
  return damage;
}

DiveLogDamage MeasureDiveLogDamage(const fs::path& original_path, const OriginalLog& original,
                                   const RobustnessOptions& options, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  DiveLogDamage total;
  const fs::path copy =
      original_path.parent_path() / ("damaged_" + original_path.filename().string());
  for (int trial = 0; trial < options.dive_log_trials; ++trial) {
    DamageCopy(original_path, copy, options.damaged_bytes, rng);
    const DiveLogDamage damage = CountDamage(copy, original, options.timeout_s);
    total.damaged_rows += damage.damaged_rows;
    total.detected += damage.detected;
  }
  return total;
}

}  // namespace

void RobustnessOptions::Check() const {
  const OptionChecks check("RobustnessOptions");
  check.AtLeast("mutants_per_kind", mutants_per_kind, 1);
  check.GreaterThan("timeout_s", timeout_s, 0.0, "s");
  check.AtLeast("dive_log_trials", dive_log_trials, 0);
  check.AtLeast("damaged_bytes", damaged_bytes, 1);
  check.Require(fs::is_directory(data_dir / "scanners") && fs::is_directory(data_dir / "scenes"),
                "data_dir", "a data folder with scanners/ and scenes/ (use --data)",
                OptionQuotedText(data_dir.string()));
}

RobustnessResult RunRobustnessBenchmark(const RobustnessOptions& options, const fs::path& scratch,
                                        const Progress& progress) {
  options.Check();
  const auto start = Clock::now();
  const fs::path seeds = scratch / "seeds";
  const fs::path workspace = scratch / "workspace";
  WriteReaderSeeds(options.data_dir, seeds);
  PrepareReaderWorkspace(workspace, options.data_dir);

  RobustnessResult result;
  std::mt19937_64 rng(options.seed);
  const std::vector<ReaderProbe>& probes = ReaderProbes();
  for (std::size_t p = 0; p < probes.size(); ++p) {
    if (progress) progress("mutated files", double(p) / double(probes.size()));
    std::vector<fs::path> files;
    for (const fs::directory_entry& entry : fs::directory_iterator(seeds / probes[p].name))
      files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    result.readers[probes[p].name] = MeasureReader(probes[p], files, workspace, options, rng);
  }
  if (progress) progress("mutated files", 1.0);

  if (options.dive_log_trials > 0) {
    if (progress) progress("damaged dive logs", 0.0);
    const fs::path v3 = scratch / "dive_v3.uwlog";
    const OriginalLog original = WriteOriginalLog(v3);
    result.dive_log = MeasureDiveLogDamage(v3, original, options, options.seed + 1);
    const fs::path v2 = scratch / "dive_v2.uwlog";
    fs::copy_file(v3, v2);
    StripChecksums(v2);
    result.dive_log_without_checksums =
        MeasureDiveLogDamage(v2, original, options, options.seed + 1);
    if (progress) progress("damaged dive logs", 1.0);
  }
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

}  // namespace uwscan::bench
