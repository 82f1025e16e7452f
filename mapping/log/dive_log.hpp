#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "scanner/lasers/scan_pattern.hpp"
#include "scanner/lasers/scanner.hpp"

// The dive log: one SQLite file per dive holding the scanner configuration it was taken with,
// every camera frame (stripe peaks, optionally the image), the vehicle's navigation and, for
// simulated dives, the ground truth. The file format is documented and versioned in
// mapping/README.md. SQLite stays inside the .cpp files.
namespace uwscan::mapping {

// The schema this uwscan writes and the newest it reads; it also reads every older one.
inline constexpr int kDiveLogSchemaVersion = 3;
inline constexpr int kOldestDiveLogSchemaVersion = 1;

enum class LogPixelFormat : std::uint8_t { kMono8 = 0, kMono16 = 1 };

// A single-channel camera frame: row-major, no padding between rows, Mono16 pixels native-endian
// uint16_t (the file stores them little-endian). bytes.size() == width * height * bytes/pixel.
struct LogImage {
  int width_px = 0;
  int height_px = 0;
  LogPixelFormat format = LogPixelFormat::kMono8;
  std::vector<std::uint8_t> bytes;
};

// How far the vehicle's navigation can be trusted (its sensors' specifications, or the noise a
// simulated dive was given): what mapping weighs navigation against scan matching with. Zero
// means "exact" (a simulated dive without drift); mapping puts a floor under each value.
struct NavigationNoise {
  double position_walk_m_per_sqrt_s = 0.0;   // random-walk density of dead-reckoned x and y
  double heading_walk_rad_per_sqrt_s = 0.0;  // random-walk density of the heading
  double speed_scale_sigma = 0.0;            // std of the DVL speed scale error (0.01 = 1 %)
  double heading_bias_sigma_rad = 0.0;       // std of the heading bias
  double depth_sigma_m = 0.0;                // white noise of the pressure depth
  double roll_pitch_sigma_rad = 0.0;         // white noise of the AHRS roll and pitch
  // Throws uwscan::Error naming the field when a value is negative or not finite.
  void Check() const;
};

struct DiveLogHeader {
  int schema_version = kDiveLogSchemaVersion;  // filled by the reader; the writer writes its own
  scanner::Scanner scanner;           // the scanner (its calibration) the dive was taken with
  scanner::ScanPattern scan_pattern;  // how the dive was scanned
  std::string scene_yaml;   // scene text when simulated, empty otherwise (a record, not read back)
  std::string created_utc;  // ISO 8601 ("2024-05-01T12:34:56Z"), set by the writer
  std::string producer;     // e.g. "uwscan simulate 0.1.0"
  // The navigation's noise model (schema version 2 on); std::nullopt when the log does not
  // say (a version 1 log, or a vehicle whose specifications were not given).
  std::optional<NavigationNoise> navigation_noise;
};

struct FrameRecord {
  std::int64_t index = 0;  // 0, 1, 2, ... consecutive, assigned by the writer (ignored on append)
  double time_s = 0.0;     // capture time
  int command = 0;         // galvo: mirror step; MEMS: line index in the scan pattern
  int sweep = 0;           // which sweep of the scan pattern
  std::vector<Eigen::Vector2d> peaks_px;  // stripe peaks (u, v), OpenCV pixel convention
  std::optional<LogImage> image;
};

// Only in simulated dives, at most one per frame.
struct GroundTruthRecord {
  Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();  // true camera pose at the frame time
  std::vector<Eigen::Vector3d> points_W;  // true surface point of each peak (same order and size)
  std::vector<std::int32_t> object_ids;   // scene object each peak lies on (same size)
};

// What the vehicle believes about its pose, from its own navigation.
struct NavigationRecord {
  double time_s = 0.0;
  Eigen::Isometry3d T_W_V = Eigen::Isometry3d::Identity();
};

// Writes a new dive log. Every Append* call is one SQLite transaction committed before it
// returns (WAL journal, synchronous=NORMAL): a process killed at any point leaves a log that
// opens and holds every frame appended before the call in progress. Not thread-safe: one
// thread at a time. Every failure throws uwscan::Error naming the file; a rejected record
// leaves nothing in the log and the next frame gets the index the rejected one would have.
// Destroying the writer syncs the log and, unless another connection has it open, turns it
// into one self-contained file (README: "Writing, crashes and power cuts").
class DiveLogWriter {
 public:
  // Creates `path` and commits the header at once. Throws uwscan::Error when the file (or a
  // stray `-wal` / `-journal` beside it, which SQLite would replay into the new file) already
  // exists, the header is invalid (scanner or scan pattern fail their checks, or are of two
  // kinds) or
  // the file cannot be created. `header.schema_version` and `header.created_utc` are ignored.
  DiveLogWriter(const std::filesystem::path& path, const DiveLogHeader& header);
  ~DiveLogWriter();
  DiveLogWriter(DiveLogWriter&&) noexcept;
  DiveLogWriter& operator=(DiveLogWriter&&) noexcept;
  DiveLogWriter(const DiveLogWriter&) = delete;
  DiveLogWriter& operator=(const DiveLogWriter&) = delete;

  // Appends a frame (and its ground truth when given) in one transaction; returns its index.
  // Throws before writing anything when time_s or a peak is not finite, the image's byte count
  // does not match its size and format, or the truth is not finite, not rigid, or its points
  // or ids are not one per peak.
  std::int64_t AppendFrame(const FrameRecord& frame, const GroundTruthRecord* truth = nullptr);

  // Appends a navigation sample, committed. Throws on a non-finite time or a non-rigid pose.
  void AppendNavigation(const NavigationRecord& nav);

  // Stores (or replaces) where the camera sits on the vehicle, committed.
  void SetVehicleMount(const Eigen::Isometry3d& T_V_C);

  // Frames committed so far.
  std::int64_t frame_count() const;

  const std::filesystem::path& path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Writes a whole dive log or none: `write` makes the log at the temporary path it is given
// (beside `path`, through a DiveLogWriter destroyed before it returns); then SQLite's files of an
// earlier log at `path` (`-wal`, `-shm`, `-journal`, which SQLite would replay into the new one)
// are removed and the new log replaces `path`. On any failure the temporary and its SQLite files
// are removed and the exception passes on: `path` keeps what it held, or stays absent.
void WriteDiveLogAtomically(const std::filesystem::path& path,
                            const std::function<void(const std::filesystem::path&)>& write);

// A damaged row that DiveLogReader::Check found.
struct DiveLogDamage {
  std::string table;      // "frames" (a frame or its ground truth), "navigation", "header", "file"
  std::int64_t row = -1;  // the frame index or the navigation sample's nav_id; -1: not a row
  std::string message;    // what the reader said, naming the file, the row and the column
};

// What DiveLogReader::Check found in a whole log.
struct DiveLogCheck {
  int schema_version = 0;
  bool checksummed = false;            // schema version 3 on: every value verified
  std::vector<std::string> integrity;  // SQLite's quick_check findings (empty: none)
  std::int64_t frames = 0;             // rows of the frames table, and how many are intact
  std::int64_t frames_intact = 0;
  // Of those, the frames whose ground truth could not be read: damaged, or in a truncated file
  // the pages where a frame's row (or its absence) would be; such a frame may have had none.
  std::int64_t frames_with_damaged_truth = 0;
  std::int64_t navigation = 0;
  std::int64_t navigation_intact = 0;
  std::vector<DiveLogDamage> damage;
  bool ok() const { return integrity.empty() && damage.empty(); }
};

// How DiveLogReader opens a log.
enum class DiveLogOpening {
  kIntact,   // a truncated file is refused, naming what it lacks
  kDamaged,  // for Check and salvage: a truncated file is read as far as it goes (a file being
             // written may show as truncated to Check while its writer checkpoints)
};

// Whether the file starts as every SQLite database does: a dive log, or another SQLite file that
// DiveLogReader refuses by name. False for a missing or unreadable file.
bool IsSqliteFile(const std::filesystem::path& path);

// Reads a dive log, read-only. Works on a log whose writer is still appending (in this or
// another process: each call sees what was committed when it starts) and on a log whose writer
// was killed (every committed frame is there). Not thread-safe: one thread at a time.
class DiveLogReader {
 public:
  // Throws uwscan::Error naming the file when it is missing, not a SQLite database, not a dive
  // log (no `meta` table), of another or a newer schema version, or lacks a table or column;
  // and, when opened as kIntact, when the file is shorter than its own header says (a copy or
  // transfer cut short: `uwscan log salvage` recovers what it holds).
  explicit DiveLogReader(const std::filesystem::path& path,
                         DiveLogOpening opening = DiveLogOpening::kIntact);
  ~DiveLogReader();
  DiveLogReader(DiveLogReader&&) noexcept;
  DiveLogReader& operator=(DiveLogReader&&) noexcept;
  DiveLogReader(const DiveLogReader&) = delete;
  DiveLogReader& operator=(const DiveLogReader&) = delete;

  const DiveLogHeader& header() const;

  // T_V_C when the writer stored it (read at each call).
  std::optional<Eigen::Isometry3d> vehicle_mount() const;

  // Frames committed at the time of the call.
  std::int64_t frame_count() const;

  // Throws uwscan::Error naming the index when there is no such frame, and naming the index
  // and column when a row is corrupt (wrong type, blob size not matching its content).
  FrameRecord ReadFrame(std::int64_t index) const;

  // The frame's ground truth, nullopt when the frame has none. Throws like ReadFrame.
  std::optional<GroundTruthRecord> ReadGroundTruth(std::int64_t index) const;

  // Calls `visit` for every frame in index order, with its ground truth when `with_truth` and
  // the frame has one (else nullptr). One query, one row in memory at a time; the frames are
  // those committed when the call starts. Throws like ReadFrame, and when an index is missing.
  void ForEachFrame(const std::function<void(const FrameRecord&, const GroundTruthRecord*)>& visit,
                    bool with_truth) const;

  // Every navigation sample, in time order (append order among equal times).
  std::vector<NavigationRecord> ReadNavigation() const;

  // Reads every row of the log, going on past damaged ones, and runs SQLite's quick_check:
  // `frame` is called for each intact frame in index order (with its ground truth, or nullptr),
  // `navigation` for each intact sample in nav_id order; either may be empty. A frame whose
  // ground truth is damaged is intact, handed over without it (nullptr), and its ground truth
  // is a damaged row of table ground_truth. A truncated file (opened as kDamaged) is an
  // integrity finding naming how much of it is missing. `progress` receives the fraction of
  // frames read. Throws only when the file cannot be read at all.
  DiveLogCheck Check(const std::function<void(const FrameRecord&, const GroundTruthRecord*)>& frame,
                     const std::function<void(const NavigationRecord&)>& navigation,
                     const std::function<void(double)>& progress = {}) const;

  const std::filesystem::path& path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace uwscan::mapping
