#include <fcntl.h>
#include <unistd.h>

#include <bit>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ctime>
#include <system_error>
#include <utility>

#include "mapping/log/dive_log.hpp"
#include "mapping/log/dive_log_format.hpp"
#include "mapping/log/row_checksums.hpp"
#include "mapping/log/sqlite_db.hpp"
#include "scanner/common/atomic_file.hpp"
#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"

// The writing half of dive_log.hpp.
namespace uwscan::mapping {
namespace {

namespace fs = std::filesystem;
using namespace dive_log_format;
using sqlite::ResetOnExit;
using sqlite::Statement;

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

// Throws, naming the log, unless the header can be written.
void CheckHeader(const DiveLogHeader& header, const std::string& name) {
  try {
    header.scanner.Check();
    header.scan_pattern.Check();
    if (header.navigation_noise) header.navigation_noise->Check();
  } catch (const Error& e) {
    throw Error(name + ": invalid header: " + e.what());
  }
  if (header.scan_pattern.kind != header.scanner.kind()) {
    throw Error(name + ": header.scan_pattern is for a " +
                scanner::ToString(header.scan_pattern.kind) + " scanner, header.scanner is " +
                scanner::ToString(header.scanner.kind()));
  }
}

// Creates the empty file exclusively: an existing file, a log being written included, is never
// overwritten, and SQLite would replay a leftover journal of an earlier file into the new one.
void CreateExclusively(const fs::path& path, const std::string& name) {
  for (const char* suffix : {"-wal", "-journal"}) {
    std::error_code ec;
    if (fs::exists(WithSuffix(path, suffix), ec)) {
      throw Error(name + ": a stray " + Quoted(WithSuffix(path, suffix)) +
                  " exists; remove it (or the log it belongs to) first");
    }
  }
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    if (errno == EEXIST) {
      throw Error(name + ": the file already exists; a dive log is never overwritten");
    }
    throw Error(name + ": cannot create (" + std::strerror(errno) + ")");
  }
  ::close(fd);
}

void CheckImage(const LogImage& image, const std::string& where) {
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

void CheckTruth(const GroundTruthRecord& truth, std::size_t peaks, const std::string& where) {
  CheckPose(truth.T_W_C, where + ": ground truth T_W_C");
  if (truth.points_W.size() != peaks || truth.object_ids.size() != peaks) {
    throw Error(where + ": ground truth has " + std::to_string(truth.points_W.size()) +
                " points and " + std::to_string(truth.object_ids.size()) +
                " object ids, expected one per peak (" + std::to_string(peaks) + ")");
  }
  for (std::size_t i = 0; i < truth.points_W.size(); ++i) {
    if (!truth.points_W[i].allFinite()) {
      throw Error(where + ": ground truth point " + std::to_string(i) + " is not finite");
    }
  }
}

// Everything about a frame that would make its row unreadable, checked before its transaction.
void CheckFrame(const FrameRecord& frame, const GroundTruthRecord* truth,
                const std::string& where) {
  if (!std::isfinite(frame.time_s)) throw Error(where + ": time_s is not finite");
  for (std::size_t i = 0; i < frame.peaks_px.size(); ++i) {
    if (!frame.peaks_px[i].allFinite()) {
      throw Error(where + ": peak " + std::to_string(i) + " is not finite");
    }
  }
  if (frame.image) CheckImage(*frame.image, where);
  if (truth) CheckTruth(*truth, frame.peaks_px.size(), where);
}

// The coordinates of packed fixed-size Eigen vectors as one array (null when there are none).
template <typename Vector>
const double* Coordinates(const std::vector<Vector>& vectors) {
  return vectors.empty() ? nullptr : vectors.front().data();
}

}  // namespace

struct DiveLogWriter::Impl {
  fs::path path;
  std::string name;  // "dive log '<path>'", the start of every error message
  sqlite::Db db;
  Statement begin, commit, rollback, insert_frame, insert_truth, insert_navigation, update_mount;
  std::int64_t frame_count = 0;
  std::vector<std::uint8_t> scratch[4];
  // The header's text columns, kept for the checksums of a vehicle mount stored later.
  std::vector<std::string> header_texts;  // byte-swapped blobs on big-endian hosts only

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

  void OpenInWalMode() {
    db = sqlite::Open(path, SQLITE_OPEN_READWRITE, kBusyTimeout_ms, name);
    const std::string application_id = "PRAGMA application_id = " + std::to_string(kApplicationId);
    sqlite::Exec(db.get(), application_id.c_str(), name, "cannot set the application id");
    // WAL: a commit appends to the -wal file, so a killed writer never leaves a half-written
    // page in the database, and readers (other processes too) read while it writes.
    Statement mode = Prepare("PRAGMA journal_mode = WAL");
    const bool stepped = sqlite3_step(mode.get()) == SQLITE_ROW;
    const auto* text = stepped ? sqlite3_column_text(mode.get(), 0) : nullptr;
    if (!text || std::string(reinterpret_cast<const char*>(text)) != "wal") {
      throw Error(name + ": cannot use a WAL journal here (a file system without shared memory?)");
    }
  }

  // The header reaches the disk at once, the file's directory entry too: a power cut never
  // loses the log itself. Afterwards the WAL is synced at checkpoints, not at each commit: a
  // frame costs a write, not a flush to disk (README: what a power cut can lose).
  void WriteHeaderDurably(const DiveLogHeader& header) {
    sqlite::Exec(db.get(), "PRAGMA synchronous = FULL", name, "cannot set synchronous mode");
    WriteHeader(header);
    sqlite::Exec(db.get(), "PRAGMA synchronous = NORMAL", name, "cannot set synchronous mode");
    SyncDirectoryOf(path);
  }

  void PrepareStatements() {
    begin = Prepare("BEGIN IMMEDIATE");
    commit = Prepare("COMMIT");
    rollback = Prepare("ROLLBACK");
    insert_frame = Prepare(
        "INSERT INTO frames (frame_index, time_s, command, sweep, peaks_px, image_width_px, "
        "image_height_px, image_format, image, checksums) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    insert_truth = Prepare(
        "INSERT INTO ground_truth (frame_index, T_W_C_tx, T_W_C_ty, T_W_C_tz, T_W_C_qx, "
        "T_W_C_qy, T_W_C_qz, T_W_C_qw, points_W, object_ids, checksums) "
        "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    insert_navigation = Prepare(
        "INSERT INTO navigation (time_s, T_W_V_tx, T_W_V_ty, T_W_V_tz, T_W_V_qx, T_W_V_qy, "
        "T_W_V_qz, T_W_V_qw, checksums) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)");
    update_mount = Prepare(
        "UPDATE header SET T_V_C_tx = ?, T_V_C_ty = ?, T_V_C_tz = ?, T_V_C_qx = ?, "
        "T_V_C_qy = ?, T_V_C_qz = ?, T_V_C_qw = ?, checksums = ?");
  }

  // The frame's row; the checksums follow the columns' order (dive_log_format.hpp).
  void InsertFrame(std::int64_t index, const FrameRecord& frame) {
    int rc = SQLITE_OK;  // the first failure of a bind
    auto bind = [&rc](int result) {
      if (rc == SQLITE_OK) rc = result;
    };
    sqlite3_stmt* s = insert_frame.get();
    ResetOnExit reset(s);
    RowChecksums checksums;
    bind(sqlite3_bind_int64(s, 1, index));
    bind(sqlite3_bind_double(s, 2, frame.time_s));
    bind(sqlite3_bind_int(s, 3, frame.command));
    bind(sqlite3_bind_int(s, 4, frame.sweep));
    for (double value : {double(index), frame.time_s, double(frame.command), double(frame.sweep)}) {
      checksums.Number(value);
    }
    const std::size_t num_peaks = frame.peaks_px.size();
    const void* peaks =
        sqlite::LittleEndianBytes(Coordinates(frame.peaks_px), 2 * num_peaks, scratch[0]);
    bind(sqlite::BindBlob(s, 5, peaks, num_peaks * sizeof(Eigen::Vector2d)));
    checksums.Bytes(peaks, num_peaks * sizeof(Eigen::Vector2d));
    if (frame.image) {
      BindImage(s, *frame.image, bind, checksums);
    } else {  // the image columns stay NULL
      for (int i = 0; i < 4; ++i) checksums.Null();
    }
    bind(sqlite::BindBlob(s, 10, checksums.blob().data(), checksums.blob().size()));
    if (rc != SQLITE_OK) sqlite::Fail(name, "cannot bind " + FrameName(index), db.get());
    if (sqlite3_step(s) != SQLITE_DONE)
      sqlite::Fail(name, "cannot insert " + FrameName(index), db.get());
  }

  // Columns 6-9 of a frame's row.
  template <typename Bind>
  void BindImage(sqlite3_stmt* s, const LogImage& image, Bind& bind, RowChecksums& checksums) {
    bind(sqlite3_bind_int(s, 6, image.width_px));
    bind(sqlite3_bind_int(s, 7, image.height_px));
    bind(sqlite3_bind_int(s, 8, static_cast<int>(image.format)));
    for (int value : {image.width_px, image.height_px, static_cast<int>(image.format)}) {
      checksums.Number(value);
    }
    const void* pixels = image.bytes.data();
    if constexpr (std::endian::native != std::endian::little) {
      if (image.format == LogPixelFormat::kMono16) {  // little-endian in the file
        scratch[1] = image.bytes;
        SwapBytePairs(scratch[1]);
        pixels = scratch[1].data();
      }
    }
    bind(sqlite::BindBlob(s, 9, pixels, image.bytes.size()));
    checksums.Bytes(pixels, image.bytes.size());
  }

  void InsertTruth(std::int64_t index, const GroundTruthRecord& truth) {
    int rc = SQLITE_OK;
    auto bind = [&rc](int result) {
      if (rc == SQLITE_OK) rc = result;
    };
    const std::size_t num_peaks = truth.points_W.size();
    sqlite3_stmt* t = insert_truth.get();
    ResetOnExit reset_truth(t);
    RowChecksums checksums;
    bind(sqlite3_bind_int64(t, 1, index));
    bind(sqlite::BindPose(t, 2, truth.T_W_C));
    checksums.Number(double(index));
    for (double value : sqlite::PoseColumns(truth.T_W_C)) checksums.Number(value);
    const void* points =
        sqlite::LittleEndianBytes(Coordinates(truth.points_W), 3 * num_peaks, scratch[2]);
    const void* ids = sqlite::LittleEndianBytes(truth.object_ids.data(), num_peaks, scratch[3]);
    bind(sqlite::BindBlob(t, 9, points, num_peaks * sizeof(Eigen::Vector3d)));
    bind(sqlite::BindBlob(t, 10, ids, num_peaks * sizeof(std::int32_t)));
    checksums.Bytes(points, num_peaks * sizeof(Eigen::Vector3d));
    checksums.Bytes(ids, num_peaks * sizeof(std::int32_t));
    bind(sqlite::BindBlob(t, 11, checksums.blob().data(), checksums.blob().size()));
    if (rc != SQLITE_OK || sqlite3_step(t) != SQLITE_DONE) {
      sqlite::Fail(name, "cannot insert the ground truth of " + FrameName(index), db.get());
    }
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
        "created_utc, producer, checksums) VALUES (1, ?, ?, ?, ?, ?, ?, ?)");
    header_texts = {scanner::ToString(header.scanner.kind()),
                    scanner::ScannerToYaml(header.scanner),
                    scanner::ScanPatternToYaml(header.scan_pattern),
                    header.scene_yaml,
                    UtcNow(),
                    header.producer};
    int column = 1;
    for (const std::string& text : header_texts) {
      // Unbound (too long) text would stay NULL and fail the NOT NULL constraint.
      sqlite3_bind_text64(head.get(), column++, text.data(), text.size(), SQLITE_STATIC,
                          SQLITE_UTF8);
    }
    const RowChecksums checksums = HeaderChecksums(nullptr);
    sqlite::BindBlob(head.get(), column, checksums.blob().data(), checksums.blob().size());
    sqlite::StepDone(handle, head.get(), name, "cannot write the header");
    if (header.navigation_noise) WriteNavigationNoise(*header.navigation_noise);
    sqlite::Exec(handle, "COMMIT", name, "cannot commit the header");
  }

  // kHeaderChecksumColumns: the texts, then the vehicle mount (NULL until stored).
  RowChecksums HeaderChecksums(const Eigen::Isometry3d* T_V_C) const {
    RowChecksums checksums;
    for (const std::string& text : header_texts) checksums.Text(text);
    if (T_V_C) {
      for (double value : sqlite::PoseColumns(*T_V_C)) checksums.Number(value);
    } else {
      for (int i = 0; i < 7; ++i) checksums.Null();
    }
    return checksums;
  }

  void WriteNavigationNoise(const NavigationNoise& noise) {
    Statement insert = Prepare(
        "INSERT INTO navigation_noise (id, position_walk_m_per_sqrt_s, "
        "heading_walk_rad_per_sqrt_s, "
        "speed_scale_sigma, heading_bias_sigma_rad, depth_sigma_m, roll_pitch_sigma_rad, "
        "checksums) "
        "VALUES (1, ?, ?, ?, ?, ?, ?, ?)");
    int column = 1;
    RowChecksums checksums;
    for (double value : {noise.position_walk_m_per_sqrt_s, noise.heading_walk_rad_per_sqrt_s,
                         noise.speed_scale_sigma, noise.heading_bias_sigma_rad, noise.depth_sigma_m,
                         noise.roll_pitch_sigma_rad}) {
      sqlite3_bind_double(insert.get(), column++, value);
      checksums.Number(value);
    }
    sqlite::BindBlob(insert.get(), column, checksums.blob().data(), checksums.blob().size());
    sqlite::StepDone(db.get(), insert.get(), name, "cannot write the navigation noise");
  }
};

DiveLogWriter::DiveLogWriter(const std::filesystem::path& path, const DiveLogHeader& header)
    : impl_(std::make_unique<Impl>()) {
  Impl& w = *impl_;
  w.path = path;
  w.name = LogName(path);
  CheckHeader(header, w.name);
  CreateExclusively(path, w.name);
  try {
    w.OpenInWalMode();
    w.WriteHeaderDurably(header);
    w.PrepareStatements();
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
  // Everything is checked before the transaction: a refused frame leaves no trace.
  CheckFrame(frame, truth, w.name + ": " + FrameName(index));
  w.InTransaction(FrameName(index), [&] {
    w.InsertFrame(index, frame);
    if (truth) w.InsertTruth(index, *truth);
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
  RowChecksums checksums;
  checksums.Number(nav.time_s);
  for (double value : sqlite::PoseColumns(nav.T_W_V)) checksums.Number(value);
  if (sqlite3_bind_double(s, 1, nav.time_s) != SQLITE_OK ||
      sqlite::BindPose(s, 2, nav.T_W_V) != SQLITE_OK ||
      sqlite::BindBlob(s, 9, checksums.blob().data(), checksums.blob().size()) != SQLITE_OK ||
      sqlite3_step(s) != SQLITE_DONE) {
    sqlite::Fail(w.name, "cannot insert a navigation sample", w.db.get());
  }  // committed: a statement outside a transaction is its own
}

void DiveLogWriter::SetVehicleMount(const Eigen::Isometry3d& T_V_C) {
  assert(impl_ && "DiveLogWriter used after being moved from");
  Impl& w = *impl_;
  CheckPose(T_V_C, w.name + ": vehicle mount T_V_C");
  sqlite3_stmt* s = w.update_mount.get();
  ResetOnExit reset(s);
  const RowChecksums checksums = w.HeaderChecksums(&T_V_C);
  if (sqlite::BindPose(s, 1, T_V_C) != SQLITE_OK ||
      sqlite::BindBlob(s, 8, checksums.blob().data(), checksums.blob().size()) != SQLITE_OK ||
      sqlite3_step(s) != SQLITE_DONE) {
    sqlite::Fail(w.name, "cannot store the vehicle mount", w.db.get());
  }  // committed, like a navigation sample
}

std::int64_t DiveLogWriter::frame_count() const { return impl_->frame_count; }

const std::filesystem::path& DiveLogWriter::path() const { return impl_->path; }

void WriteDiveLogAtomically(const std::filesystem::path& path,
                            const std::function<void(const std::filesystem::path&)>& write) {
  const std::filesystem::path temporary = TemporaryBeside(path);
  const auto remove_with_sqlite_files = [](const std::filesystem::path& log, bool itself) {
    std::error_code ignored;
    for (const char* suffix : {"-wal", "-shm", "-journal"})
      std::filesystem::remove(log.string() + suffix, ignored);
    if (itself) std::filesystem::remove(log, ignored);
  };
  try {
    write(temporary);
    // SQLite keeps its side files beside the file a link ends at.
    remove_with_sqlite_files(FollowLinks(path), false);
    ReplaceWithTemporary(temporary, path);
  } catch (...) {
    remove_with_sqlite_files(temporary, true);
    throw;
  }
}

}  // namespace uwscan::mapping
