#include "mapping/dive_log.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cassert>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ctime>
#include <set>
#include <system_error>
#include <utility>

#include "mapping/sqlite_db.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping {
namespace {

namespace fs = std::filesystem;
using sqlite::ResetOnExit;
using sqlite::Row;
using sqlite::Statement;

// The schema of version 1, documented in mapping/README.md. A later version may add tables and
// columns; a reader refuses versions it does not know.
constexpr const char* kSchemaSql = R"sql(
CREATE TABLE meta (key TEXT PRIMARY KEY NOT NULL, value NOT NULL);
CREATE TABLE header (
  id INTEGER PRIMARY KEY CHECK (id = 1),
  scanner_kind TEXT NOT NULL, scanner_yaml TEXT NOT NULL, scan_pattern_yaml TEXT NOT NULL,
  scene_yaml TEXT NOT NULL,
  created_utc TEXT NOT NULL, producer TEXT NOT NULL,
  T_V_C_tx REAL, T_V_C_ty REAL, T_V_C_tz REAL,
  T_V_C_qx REAL, T_V_C_qy REAL, T_V_C_qz REAL, T_V_C_qw REAL);
CREATE TABLE frames (
  frame_index INTEGER PRIMARY KEY, time_s REAL NOT NULL,
  command INTEGER NOT NULL, sweep INTEGER NOT NULL, peaks_px BLOB NOT NULL,
  image_width_px INTEGER, image_height_px INTEGER, image_format INTEGER, image BLOB);
CREATE TABLE ground_truth (
  frame_index INTEGER PRIMARY KEY REFERENCES frames (frame_index),
  T_W_C_tx REAL NOT NULL, T_W_C_ty REAL NOT NULL, T_W_C_tz REAL NOT NULL,
  T_W_C_qx REAL NOT NULL, T_W_C_qy REAL NOT NULL, T_W_C_qz REAL NOT NULL,
  T_W_C_qw REAL NOT NULL, points_W BLOB NOT NULL, object_ids BLOB NOT NULL);
CREATE TABLE navigation (
  nav_id INTEGER PRIMARY KEY, time_s REAL NOT NULL,
  T_W_V_tx REAL NOT NULL, T_W_V_ty REAL NOT NULL, T_W_V_tz REAL NOT NULL,
  T_W_V_qx REAL NOT NULL, T_W_V_qy REAL NOT NULL, T_W_V_qz REAL NOT NULL,
  T_W_V_qw REAL NOT NULL);
)sql";

// "UWDL": lets `file` and other tools tell a dive log from any other SQLite database.
constexpr std::int32_t kApplicationId = 0x5557444C;

// How long a connection waits for another one's lock (a checkpoint, a second writer) before
// failing with "database is locked".
constexpr int kBusyTimeout_ms = 5000;

// The file keeps rotations as unit quaternions: a rotation further than this from orthonormal
// is refused rather than silently changed.
constexpr double kRigidTolerance = 1e-6;

// Selected by every frame query and decoded by DecodeFrame, in this order.
constexpr const char* kFrameColumns =
    "f.frame_index, f.time_s, f.command, f.sweep, f.peaks_px, f.image_width_px, "
    "f.image_height_px, f.image_format, f.image";
constexpr int kNumFrameColumns = 9;
// Selected by ground truth queries and decoded by DecodeTruth, in this order.
constexpr const char* kTruthColumns =
    "g.frame_index IS NOT NULL, g.T_W_C_tx, g.T_W_C_ty, g.T_W_C_tz, g.T_W_C_qx, g.T_W_C_qy, "
    "g.T_W_C_qz, g.T_W_C_qw, g.points_W, g.object_ids";

static_assert(sizeof(Eigen::Vector2d) == 2 * sizeof(double), "peaks must be packed doubles");
static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "points must be packed doubles");

std::string Quoted(const fs::path& path) {
  // Appended piecewise: GCC 12 warns falsely (-Wrestrict) on "'" + std::string.
  std::string quoted(1, '\'');
  quoted.append(path.string());
  quoted.push_back('\'');
  return quoted;
}

std::string LogName(const fs::path& path) { return "dive log " + Quoted(path); }

std::string FrameName(std::int64_t index) { return "frame " + std::to_string(index); }

fs::path WithSuffix(const fs::path& path, const char* suffix) {
  fs::path result = path;
  result += suffix;
  return result;
}

// Makes the creation of a file durable. Some file systems refuse fsync on a directory; the
// log is then as durable as they make it, which is no reason to refuse to write it.
void SyncDirectoryOf(const fs::path& path) {
  const fs::path directory = path.has_parent_path() ? path.parent_path() : fs::path(".");
  const int fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

std::string UtcNow() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

// Throws unless T is finite and rigid.
void CheckPose(const Eigen::Isometry3d& T, const std::string& where) {
  if (!T.linear().allFinite() || !T.translation().allFinite()) {
    throw Error(where + " is not finite");
  }
  const Eigen::Matrix3d R = T.linear();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > kRigidTolerance ||
      R.determinant() <= 0.0) {
    throw Error(where + " is not a rigid transform (rotation not orthonormal with det +1)");
  }
}

// Mono16 pixels between native and little-endian order (big-endian hosts only).
void SwapBytePairs(std::vector<std::uint8_t>& bytes) {
  for (std::size_t i = 0; i + 1 < bytes.size(); i += 2) std::swap(bytes[i], bytes[i + 1]);
}

// The coordinates of packed fixed-size Eigen vectors as one array (null when there are none).
template <typename Vector>
const double* Coordinates(const std::vector<Vector>& vectors) {
  return vectors.empty() ? nullptr : vectors.front().data();
}

// kFrameColumns from column 0; the row's context names the frame.
FrameRecord DecodeFrame(const Row& row, std::int64_t index) {
  FrameRecord frame;
  frame.index = index;
  frame.time_s = row.Real(1);
  frame.command = row.Int(2);
  frame.sweep = row.Int(3);
  frame.peaks_px = row.Items<Eigen::Vector2d, double>(4, -1);
  if (!row.IsNull(5) || !row.IsNull(6) || !row.IsNull(7) || !row.IsNull(8)) {
    LogImage image;
    image.width_px = row.Int(5);
    image.height_px = row.Int(6);
    if (image.width_px <= 0) row.Corrupt(5, "is not positive");
    if (image.height_px <= 0) row.Corrupt(6, "is not positive");
    const std::int64_t format = row.Integer(7);
    if (format != 0 && format != 1) row.Corrupt(7, "is neither 0 (Mono8) nor 1 (Mono16)");
    image.format = static_cast<LogPixelFormat>(format);
    const std::int64_t bytes = std::int64_t{image.width_px} * image.height_px * (format + 1);
    image.bytes = row.Items<std::uint8_t>(8, bytes);
    if constexpr (std::endian::native != std::endian::little) {
      if (image.format == LogPixelFormat::kMono16) SwapBytePairs(image.bytes);
    }
    frame.image = std::move(image);
  }
  return frame;
}

// kTruthColumns from column `first`; nullopt when the frame has no ground truth.
std::optional<GroundTruthRecord> DecodeTruth(const Row& row, int first, std::size_t num_peaks) {
  if (row.Integer(first) == 0) return std::nullopt;
  GroundTruthRecord truth;
  truth.T_W_C = row.Pose(first + 1);
  truth.points_W = row.Items<Eigen::Vector3d, double>(first + 8, std::int64_t(num_peaks));
  truth.object_ids = row.Items<std::int32_t>(first + 9, std::int64_t(num_peaks));
  return truth;
}

}  // namespace

// ======================================= writer =======================================

struct DiveLogWriter::Impl {
  fs::path path;
  std::string name;  // "dive log '<path>'", the start of every error message
  sqlite::Db db;
  Statement begin, commit, rollback, insert_frame, insert_truth, insert_navigation, update_mount;
  std::int64_t frame_count = 0;
  std::vector<std::uint8_t> scratch[4];  // byte-swapped blobs on big-endian hosts only

  // A finished log goes back to a rollback journal, which checkpoints (syncing everything)
  // and removes the WAL: it is then one self-contained file that read-only connections open
  // without creating -wal and -shm files beside it. While another connection has the log open
  // the switch would have to wait for it; it is skipped, the log stays valid in WAL mode, and
  // the WAL is synced here instead, so that closing always makes every commit durable.
  ~Impl() {
    if (!db) return;
    sqlite3_busy_timeout(db.get(), 0);
    sqlite3_stmt* raw = nullptr;
    sqlite3_prepare_v2(db.get(), "PRAGMA journal_mode = DELETE", -1, &raw, nullptr);
    const Statement mode(raw);
    const unsigned char* now = raw && sqlite3_step(raw) == SQLITE_ROW  // the mode in force
                                   ? sqlite3_column_text(raw, 0)
                                   : nullptr;
    const bool switched = now && std::strcmp(reinterpret_cast<const char*>(now), "delete") == 0;
    if (!switched) {
      const int fd = ::open(WithSuffix(path, "-wal").c_str(), O_RDONLY | O_CLOEXEC);
      if (fd >= 0) {
        ::fsync(fd);
        ::close(fd);
      }
    }
  }

  // Runs `body` between BEGIN IMMEDIATE and COMMIT, rolling back on any failure, so that a
  // record is in the log entirely or not at all. IMMEDIATE takes the write lock up front: a
  // deferred transaction that turns into a write can fail on a lock without waiting for it.
  template <typename Body>
  void InTransaction(const std::string& what, Body&& body) {
    sqlite::StepDone(db.get(), begin.get(), name, "cannot begin a transaction for " + what);
    try {
      body();
      sqlite::StepDone(db.get(), commit.get(), name, "cannot commit " + what);
    } catch (...) {
      if (!sqlite3_get_autocommit(db.get())) {
        sqlite3_step(rollback.get());
        sqlite3_reset(rollback.get());
      }
      throw;
    }
  }

  Statement Prepare(const char* sql) const {
    // Prepared once: parsing SQL for every frame would cost more than writing the frame.
    return sqlite::Prepare(db.get(), sql, SQLITE_PREPARE_PERSISTENT, name, "cannot prepare");
  }

  // Creates the tables and writes the header in one transaction.
  void WriteHeader(const DiveLogHeader& header) {
    sqlite3* handle = db.get();
    sqlite::Exec(handle, "BEGIN IMMEDIATE", name, "cannot begin writing the header");
    sqlite::Exec(handle, kSchemaSql, name, "cannot create the tables");
    Statement meta = Prepare("INSERT INTO meta (key, value) VALUES ('schema_version', ?)");
    sqlite3_bind_int(meta.get(), 1, kDiveLogSchemaVersion);
    sqlite::StepDone(handle, meta.get(), name, "cannot write the schema version");
    Statement head = Prepare(
        "INSERT INTO header (id, scanner_kind, scanner_yaml, scan_pattern_yaml, scene_yaml, "
        "created_utc, producer) VALUES (1, ?, ?, ?, ?, ?, ?)");
    const std::string created_utc = UtcNow();
    int column = 1;
    for (const std::string* text : {&header.scanner_kind, &header.scanner_yaml,
                                    &header.scan_pattern_yaml, &header.scene_yaml,
                                    &created_utc, &header.producer}) {
      // Unbound (too long) text would stay NULL and fail the NOT NULL constraint.
      sqlite3_bind_text64(head.get(), column++, text->data(), text->size(), SQLITE_STATIC,
                          SQLITE_UTF8);
    }
    sqlite::StepDone(handle, head.get(), name, "cannot write the header");
    sqlite::Exec(handle, "COMMIT", name, "cannot commit the header");
  }
};

DiveLogWriter::DiveLogWriter(const std::filesystem::path& path, const DiveLogHeader& header)
    : impl_(std::make_unique<Impl>()) {
  Impl& w = *impl_;
  w.path = path;
  w.name = LogName(path);
  if (header.scanner_kind != "galvo" && header.scanner_kind != "mems") {
    throw Error(w.name + ": header.scanner_kind is '" + header.scanner_kind +
                "', expected 'galvo' or 'mems'");
  }
  if (header.scanner_yaml.empty()) {
    throw Error(w.name +
                ": header.scanner_yaml is empty; a dive log must carry the scanner "
                "configuration it was taken with");
  }
  // SQLite would replay a leftover journal of an earlier file into the new one.
  for (const char* suffix : {"-wal", "-journal"}) {
    std::error_code ec;
    if (fs::exists(WithSuffix(path, suffix), ec)) {
      throw Error(w.name + ": a stray " + Quoted(WithSuffix(path, suffix)) +
                  " exists; remove it (or the log it belongs to) first");
    }
  }
  // Created exclusively: an existing file, a log being written included, is never overwritten.
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    if (errno == EEXIST) {
      throw Error(w.name + ": the file already exists; a dive log is never overwritten");
    }
    throw Error(w.name + ": cannot create (" + std::strerror(errno) + ")");
  }
  ::close(fd);

  try {
    w.db = sqlite::Open(path, SQLITE_OPEN_READWRITE, kBusyTimeout_ms, w.name);
    sqlite3* db = w.db.get();
    const std::string application_id = "PRAGMA application_id = " + std::to_string(kApplicationId);
    sqlite::Exec(db, application_id.c_str(), w.name, "cannot set the application id");
    {
      // WAL: a commit appends to the -wal file, so a killed writer never leaves a half-written
      // page in the database, and readers (other processes too) read while it writes.
      Statement mode = w.Prepare("PRAGMA journal_mode = WAL");
      const bool stepped = sqlite3_step(mode.get()) == SQLITE_ROW;
      const auto* text = stepped ? sqlite3_column_text(mode.get(), 0) : nullptr;
      if (!text || std::string(reinterpret_cast<const char*>(text)) != "wal") {
        throw Error(w.name +
                    ": cannot use a WAL journal here (a file system without shared "
                    "memory?)");
      }
    }
    // The header reaches the disk at once, the file's directory entry too: a power cut never
    // loses the log itself. Afterwards the WAL is synced at checkpoints, not at each commit: a
    // frame costs a write, not a flush to disk (README: what a power cut can lose).
    sqlite::Exec(db, "PRAGMA synchronous = FULL", w.name, "cannot set synchronous mode");
    w.WriteHeader(header);
    sqlite::Exec(db, "PRAGMA synchronous = NORMAL", w.name, "cannot set synchronous mode");
    SyncDirectoryOf(path);

    w.begin = w.Prepare("BEGIN IMMEDIATE");
    w.commit = w.Prepare("COMMIT");
    w.rollback = w.Prepare("ROLLBACK");
    w.insert_frame = w.Prepare(
        "INSERT INTO frames (frame_index, time_s, command, sweep, peaks_px, image_width_px, "
        "image_height_px, image_format, image) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)");
    w.insert_truth = w.Prepare(
        "INSERT INTO ground_truth (frame_index, T_W_C_tx, T_W_C_ty, T_W_C_tz, T_W_C_qx, "
        "T_W_C_qy, T_W_C_qz, T_W_C_qw, points_W, object_ids) "
        "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    w.insert_navigation = w.Prepare(
        "INSERT INTO navigation (time_s, T_W_V_tx, T_W_V_ty, T_W_V_tz, T_W_V_qx, T_W_V_qy, "
        "T_W_V_qz, T_W_V_qw) VALUES (?, ?, ?, ?, ?, ?, ?, ?)");
    w.update_mount = w.Prepare(
        "UPDATE header SET T_V_C_tx = ?, T_V_C_ty = ?, T_V_C_tz = ?, T_V_C_qx = ?, "
        "T_V_C_qy = ?, T_V_C_qz = ?, T_V_C_qw = ?");
  } catch (...) {
    // The file is ours (created exclusively above): leave nothing half-made behind.
    impl_.reset();
    std::error_code ec;
    for (const char* suffix : {"", "-wal", "-shm", "-journal"}) {
      fs::remove(WithSuffix(path, suffix), ec);
    }
    throw;
  }
}

DiveLogWriter::~DiveLogWriter() = default;
DiveLogWriter::DiveLogWriter(DiveLogWriter&&) noexcept = default;
DiveLogWriter& DiveLogWriter::operator=(DiveLogWriter&&) noexcept = default;

std::int64_t DiveLogWriter::AppendFrame(const FrameRecord& frame, const GroundTruthRecord* truth) {
  assert(impl_ && "DiveLogWriter used after being moved from");
  Impl& w = *impl_;
  const std::int64_t index = w.frame_count;
  const std::string where = w.name + ": " + FrameName(index);

  // Everything is checked before the transaction: a refused frame leaves no trace.
  if (!std::isfinite(frame.time_s)) throw Error(where + ": time_s is not finite");
  for (std::size_t i = 0; i < frame.peaks_px.size(); ++i) {
    if (!frame.peaks_px[i].allFinite()) {
      throw Error(where + ": peak " + std::to_string(i) + " is not finite");
    }
  }
  if (frame.image) {
    const LogImage& image = *frame.image;
    if (image.width_px <= 0 || image.height_px <= 0) {
      throw Error(where + ": image size " + std::to_string(image.width_px) + "x" +
                  std::to_string(image.height_px) + " px, expected at least 1x1");
    }
    if (image.format != LogPixelFormat::kMono8 && image.format != LogPixelFormat::kMono16) {
      throw Error(where + ": image format " + std::to_string(static_cast<int>(image.format)) +
                  " is neither Mono8 nor Mono16");
    }
    const std::uint64_t expected = std::uint64_t(image.width_px) * std::uint64_t(image.height_px) *
                                   (image.format == LogPixelFormat::kMono8 ? 1 : 2);
    if (image.bytes.size() != expected) {
      throw Error(where + ": image holds " + std::to_string(image.bytes.size()) +
                  " bytes, expected " + std::to_string(expected) + " for its size and format");
    }
  }
  if (truth) {
    CheckPose(truth->T_W_C, where + ": ground truth T_W_C");
    if (truth->points_W.size() != frame.peaks_px.size() ||
        truth->object_ids.size() != frame.peaks_px.size()) {
      throw Error(where + ": ground truth has " + std::to_string(truth->points_W.size()) +
                  " points and " + std::to_string(truth->object_ids.size()) +
                  " object ids, expected one per peak (" + std::to_string(frame.peaks_px.size()) +
                  ")");
    }
    for (std::size_t i = 0; i < truth->points_W.size(); ++i) {
      if (!truth->points_W[i].allFinite()) {
        throw Error(where + ": ground truth point " + std::to_string(i) + " is not finite");
      }
    }
  }

  w.InTransaction(FrameName(index), [&] {
    int rc = SQLITE_OK;  // the first failure of a bind
    auto bind = [&rc](int result) {
      if (rc == SQLITE_OK) rc = result;
    };
    sqlite3_stmt* s = w.insert_frame.get();
    ResetOnExit reset(s);
    bind(sqlite3_bind_int64(s, 1, index));
    bind(sqlite3_bind_double(s, 2, frame.time_s));
    bind(sqlite3_bind_int(s, 3, frame.command));
    bind(sqlite3_bind_int(s, 4, frame.sweep));
    const std::size_t num_peaks = frame.peaks_px.size();
    bind(sqlite::BindBlob(
        s, 5, sqlite::LittleEndianBytes(Coordinates(frame.peaks_px), 2 * num_peaks, w.scratch[0]),
        num_peaks * sizeof(Eigen::Vector2d)));
    if (frame.image) {  // else the image columns stay NULL
      const LogImage& image = *frame.image;
      bind(sqlite3_bind_int(s, 6, image.width_px));
      bind(sqlite3_bind_int(s, 7, image.height_px));
      bind(sqlite3_bind_int(s, 8, static_cast<int>(image.format)));
      const void* pixels = image.bytes.data();
      if constexpr (std::endian::native != std::endian::little) {
        if (image.format == LogPixelFormat::kMono16) {  // little-endian in the file
          w.scratch[1] = image.bytes;
          SwapBytePairs(w.scratch[1]);
          pixels = w.scratch[1].data();
        }
      }
      bind(sqlite::BindBlob(s, 9, pixels, image.bytes.size()));
    }
    if (rc != SQLITE_OK) sqlite::Fail(w.name, "cannot bind " + FrameName(index), w.db.get());
    if (sqlite3_step(s) != SQLITE_DONE) {
      sqlite::Fail(w.name, "cannot insert " + FrameName(index), w.db.get());
    }
    if (!truth) return;

    sqlite3_stmt* t = w.insert_truth.get();
    ResetOnExit reset_truth(t);
    bind(sqlite3_bind_int64(t, 1, index));
    bind(sqlite::BindPose(t, 2, truth->T_W_C));
    bind(sqlite::BindBlob(
        t, 9, sqlite::LittleEndianBytes(Coordinates(truth->points_W), 3 * num_peaks, w.scratch[2]),
        num_peaks * sizeof(Eigen::Vector3d)));
    bind(sqlite::BindBlob(
        t, 10, sqlite::LittleEndianBytes(truth->object_ids.data(), num_peaks, w.scratch[3]),
        num_peaks * sizeof(std::int32_t)));
    if (rc != SQLITE_OK || sqlite3_step(t) != SQLITE_DONE) {
      sqlite::Fail(w.name, "cannot insert the ground truth of " + FrameName(index), w.db.get());
    }
  });
  return w.frame_count++;
}

void DiveLogWriter::AppendNavigation(const NavigationRecord& nav) {
  assert(impl_ && "DiveLogWriter used after being moved from");
  Impl& w = *impl_;
  const std::string where = w.name + ": navigation sample";
  if (!std::isfinite(nav.time_s)) throw Error(where + ": time_s is not finite");
  CheckPose(nav.T_W_V, where + " at " + std::to_string(nav.time_s) + " s: T_W_V");
  sqlite3_stmt* s = w.insert_navigation.get();
  ResetOnExit reset(s);
  if (sqlite3_bind_double(s, 1, nav.time_s) != SQLITE_OK ||
      sqlite::BindPose(s, 2, nav.T_W_V) != SQLITE_OK || sqlite3_step(s) != SQLITE_DONE) {
    sqlite::Fail(w.name, "cannot insert a navigation sample", w.db.get());
  }  // committed: a statement outside a transaction is its own
}

void DiveLogWriter::SetVehicleMount(const Eigen::Isometry3d& T_V_C) {
  assert(impl_ && "DiveLogWriter used after being moved from");
  Impl& w = *impl_;
  CheckPose(T_V_C, w.name + ": vehicle mount T_V_C");
  sqlite3_stmt* s = w.update_mount.get();
  ResetOnExit reset(s);
  if (sqlite::BindPose(s, 1, T_V_C) != SQLITE_OK || sqlite3_step(s) != SQLITE_DONE) {
    sqlite::Fail(w.name, "cannot store the vehicle mount", w.db.get());
  }  // committed, like a navigation sample
}

std::int64_t DiveLogWriter::frame_count() const { return impl_->frame_count; }

const std::filesystem::path& DiveLogWriter::path() const { return impl_->path; }

// ======================================= reader =======================================

struct DiveLogReader::Impl {
  fs::path path;
  std::string name;  // "dive log '<path>'", the start of every error message
  sqlite::Db db;
  DiveLogHeader header;
  Statement frame_by_index, truth_by_index, last_index, mount, navigation;

  // Prepared at open, so that a table or column missing from the file shows there.
  Statement Prepare(const std::string& sql, unsigned flags = SQLITE_PREPARE_PERSISTENT) const {
    return sqlite::Prepare(
        db.get(), sql, flags, name,
        "does not match schema version " + std::to_string(kDiveLogSchemaVersion));
  }

  // The names of the file's tables. The first read of the file: where a file that is not
  // SQLite shows.
  std::set<std::string> Tables() const {
    auto fail = [&] {
      if (sqlite3_errcode(db.get()) == SQLITE_NOTADB) {
        throw Error(name + " is not a SQLite database");
      }
      sqlite::Fail(name, "cannot read the list of tables", db.get());
    };
    sqlite3_stmt* raw = nullptr;
    const char* sql = "SELECT name FROM sqlite_master WHERE type = 'table'";
    if (sqlite3_prepare_v2(db.get(), sql, -1, &raw, nullptr) != SQLITE_OK) fail();
    const Statement list(raw);
    std::set<std::string> tables;
    int rc;
    while ((rc = sqlite3_step(raw)) == SQLITE_ROW) {
      if (const unsigned char* table = sqlite3_column_text(raw, 0)) {
        tables.insert(reinterpret_cast<const char*>(table));
      }
    }
    if (rc != SQLITE_DONE) fail();
    return tables;
  }

  void ReadSchemaVersion() {
    Statement meta = Prepare("SELECT value FROM meta WHERE key = 'schema_version'", 0);
    int rc = sqlite3_step(meta.get());
    if (rc == SQLITE_DONE) throw Error(name + ": table meta has no schema_version");
    if (rc != SQLITE_ROW) sqlite::Fail(name, "cannot read the schema version", db.get());
    header.schema_version = Row(meta.get(), name, "table meta, key schema_version").Int(0);
    if (header.schema_version != kDiveLogSchemaVersion) {
      throw Error(name + " has schema version " + std::to_string(header.schema_version) +
                  ", this uwscan reads " + std::to_string(kDiveLogSchemaVersion));
    }
  }

  void ReadHeader() {
    Statement head = Prepare(
        "SELECT scanner_kind, scanner_yaml, scan_pattern_yaml, scene_yaml, created_utc, producer "
        "FROM header",
        0);
    int rc = sqlite3_step(head.get());
    if (rc == SQLITE_DONE) throw Error(name + ": table header is empty");
    if (rc != SQLITE_ROW) sqlite::Fail(name, "cannot read the header", db.get());
    const Row row(head.get(), name, "table header");
    header.scanner_kind = row.Text(0);
    header.scanner_yaml = row.Text(1);
    header.scan_pattern_yaml = row.Text(2);
    header.scene_yaml = row.Text(3);
    header.created_utc = row.Text(4);
    header.producer = row.Text(5);
    rc = sqlite3_step(head.get());
    if (rc == SQLITE_ROW) throw Error(name + ": table header has more than one row");
    if (rc != SQLITE_DONE) sqlite::Fail(name, "cannot read the header", db.get());
  }

  [[noreturn]] void NoSuchFrame(std::int64_t index, std::int64_t count) const {
    throw Error(name + " has no " + FrameName(index) + " (it holds " + std::to_string(count) +
                " frames)");
  }
};

DiveLogReader::DiveLogReader(const std::filesystem::path& path) : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.path = path;
  r.name = LogName(path);
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(r.name + ": no such file");
  if (!fs::is_regular_file(path, ec)) throw Error(r.name + ": not a regular file");

  r.db = sqlite::Open(path, SQLITE_OPEN_READONLY, kBusyTimeout_ms, r.name);
  // Checks each b-tree cell against its page as it is read: damage fails cleanly and early.
  sqlite::Exec(r.db.get(), "PRAGMA cell_size_check = ON", r.name, "cannot enable cell checks");

  const std::set<std::string> tables = r.Tables();
  if (!tables.contains("meta")) {
    throw Error(r.name + " is not a uwscan dive log (it has no table 'meta')");
  }
  r.ReadSchemaVersion();
  for (const char* table : {"header", "frames", "ground_truth", "navigation"}) {
    if (!tables.contains(table)) {
      throw Error(r.name + " has no table '" + table + "' (schema version " +
                  std::to_string(kDiveLogSchemaVersion) +
                  " has meta, header, frames, ground_truth and navigation)");
    }
  }
  r.ReadHeader();

  r.frame_by_index =
      r.Prepare(std::string("SELECT ") + kFrameColumns + " FROM frames f WHERE f.frame_index = ?");
  // length() reads a blob's size from the record header, without reading the blob.
  r.truth_by_index = r.Prepare(std::string("SELECT length(f.peaks_px), ") + kTruthColumns +
                               " FROM frames f LEFT JOIN ground_truth g"
                               " ON g.frame_index = f.frame_index WHERE f.frame_index = ?");
  // The largest primary key is found without a scan; indices run from 0 without gaps.
  r.last_index = r.Prepare("SELECT max(frame_index) FROM frames");
  r.mount = r.Prepare(
      "SELECT T_V_C_tx, T_V_C_ty, T_V_C_tz, T_V_C_qx, T_V_C_qy, T_V_C_qz, T_V_C_qw FROM header");
  r.navigation = r.Prepare(
      "SELECT nav_id, time_s, T_W_V_tx, T_W_V_ty, T_W_V_tz, T_W_V_qx, T_W_V_qy, T_W_V_qz, "
      "T_W_V_qw FROM navigation ORDER BY time_s, nav_id");
}

DiveLogReader::~DiveLogReader() = default;
DiveLogReader::DiveLogReader(DiveLogReader&&) noexcept = default;
DiveLogReader& DiveLogReader::operator=(DiveLogReader&&) noexcept = default;

const DiveLogHeader& DiveLogReader::header() const { return impl_->header; }

std::optional<Eigen::Isometry3d> DiveLogReader::vehicle_mount() const {
  const Impl& r = *impl_;
  sqlite3_stmt* s = r.mount.get();
  ResetOnExit reset(s);
  if (sqlite3_step(s) != SQLITE_ROW)
    sqlite::Fail(r.name, "cannot read the vehicle mount", r.db.get());
  const Row row(s, r.name, "table header");
  for (int i = 0; i < 7; ++i) {
    if (!row.IsNull(i)) return row.Pose(0);
  }
  return std::nullopt;
}

std::int64_t DiveLogReader::frame_count() const {
  const Impl& r = *impl_;
  sqlite3_stmt* s = r.last_index.get();
  ResetOnExit reset(s);
  if (sqlite3_step(s) != SQLITE_ROW) sqlite::Fail(r.name, "cannot count the frames", r.db.get());
  if (sqlite3_column_type(s, 0) == SQLITE_NULL) return 0;
  return sqlite3_column_int64(s, 0) + 1;
}

FrameRecord DiveLogReader::ReadFrame(std::int64_t index) const {
  const Impl& r = *impl_;
  sqlite3_stmt* s = r.frame_by_index.get();
  {
    ResetOnExit reset(s);
    sqlite3_bind_int64(s, 1, index);
    const int rc = sqlite3_step(s);
    if (rc == SQLITE_ROW) return DecodeFrame(Row(s, r.name, FrameName(index)), index);
    if (rc != SQLITE_DONE) sqlite::Fail(r.name, "cannot read " + FrameName(index), r.db.get());
  }
  r.NoSuchFrame(index, frame_count());
}

std::optional<GroundTruthRecord> DiveLogReader::ReadGroundTruth(std::int64_t index) const {
  const Impl& r = *impl_;
  sqlite3_stmt* s = r.truth_by_index.get();
  {
    ResetOnExit reset(s);
    sqlite3_bind_int64(s, 1, index);
    const int rc = sqlite3_step(s);
    if (rc == SQLITE_ROW) {
      const Row row(s, r.name, FrameName(index));
      const std::int64_t peak_bytes = row.Integer(0);
      if (peak_bytes % std::int64_t{sizeof(Eigen::Vector2d)} != 0) {
        row.Corrupt(0, "is " + std::to_string(peak_bytes) + ", not a multiple of 16");
      }
      return DecodeTruth(row, 1, std::size_t(peak_bytes) / sizeof(Eigen::Vector2d));
    }
    if (rc != SQLITE_DONE) {
      sqlite::Fail(r.name, "cannot read the ground truth of " + FrameName(index), r.db.get());
    }
  }
  r.NoSuchFrame(index, frame_count());
}

void DiveLogReader::ForEachFrame(
    const std::function<void(const FrameRecord&, const GroundTruthRecord*)>& visit,
    bool with_truth) const {
  const Impl& r = *impl_;
  // A statement of its own, so that `visit` may call any reader method, this one included.
  const std::string sql =
      with_truth ? std::string("SELECT ") + kFrameColumns + ", " + kTruthColumns +
                       " FROM frames f LEFT JOIN ground_truth g USING (frame_index)"
                       " ORDER BY f.frame_index"
                 : std::string("SELECT ") + kFrameColumns + " FROM frames f ORDER BY f.frame_index";
  const Statement statement = r.Prepare(sql, 0);
  sqlite3_stmt* s = statement.get();
  std::int64_t expected = 0;
  int rc;
  while ((rc = sqlite3_step(s)) == SQLITE_ROW) {
    const Row row(s, r.name, FrameName(expected));
    const std::int64_t index = row.Integer(0);
    if (index != expected) {
      throw Error(r.name + ": " + FrameName(expected) + " is missing (the next is " +
                  std::to_string(index) + ")");
    }
    const FrameRecord frame = DecodeFrame(row, index);
    if (with_truth) {
      const std::optional<GroundTruthRecord> truth =
          DecodeTruth(row, kNumFrameColumns, frame.peaks_px.size());
      visit(frame, truth ? &*truth : nullptr);
    } else {
      visit(frame, nullptr);
    }
    ++expected;
  }
  if (rc != SQLITE_DONE) sqlite::Fail(r.name, "cannot read " + FrameName(expected), r.db.get());
}

std::vector<NavigationRecord> DiveLogReader::ReadNavigation() const {
  const Impl& r = *impl_;
  sqlite3_stmt* s = r.navigation.get();
  ResetOnExit reset(s);
  std::vector<NavigationRecord> samples;
  int rc;
  while ((rc = sqlite3_step(s)) == SQLITE_ROW) {
    const Row row(s, r.name, "navigation sample " + std::to_string(sqlite3_column_int64(s, 0)));
    samples.push_back({row.Real(1), row.Pose(2)});
  }
  if (rc != SQLITE_DONE) sqlite::Fail(r.name, "cannot read the navigation", r.db.get());
  return samples;
}

const std::filesystem::path& DiveLogReader::path() const { return impl_->path; }

}  // namespace uwscan::mapping
