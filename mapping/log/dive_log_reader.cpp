#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "mapping/log/dive_log.hpp"
#include "mapping/log/dive_log_format.hpp"
#include "mapping/log/sqlite_db.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"
#include "scanner/lasers/scanner_file.hpp"

// The reading half of dive_log.hpp.
namespace uwscan::mapping {
namespace {

namespace fs = std::filesystem;
using namespace dive_log_format;
using sqlite::ResetOnExit;
using sqlite::Row;
using sqlite::Statement;

// A table's checksums column, or NULL in a log older than the checksums.
std::string Checksums(const char* table, bool checksummed) {
  return checksummed ? std::string(table) + ".checksums" : std::string("NULL");
}

// Selected by every frame query and decoded by DecodeFrame, in this order: the columns the
// checksums cover (dive_log_format.hpp), then the checksums.
std::string FrameColumns(bool checksummed) {
  return "f.frame_index, f.time_s, f.command, f.sweep, f.peaks_px, f.image_width_px, "
         "f.image_height_px, f.image_format, f.image, " +
         Checksums("f", checksummed);
}
constexpr int kNumFrameColumns = 10;
// Selected by ground truth queries and decoded by DecodeTruth, in this order (frame_index is
// NULL when the frame has no ground truth).
std::string TruthColumns(bool checksummed) {
  return "g.frame_index, g.T_W_C_tx, g.T_W_C_ty, g.T_W_C_tz, g.T_W_C_qx, g.T_W_C_qy, "
         "g.T_W_C_qz, g.T_W_C_qw, g.points_W, g.object_ids, " +
         Checksums("g", checksummed);
}

// FrameColumns from column 0; the row's context names the frame.
FrameRecord DecodeFrame(const Row& row, std::int64_t index, bool checksummed) {
  if (checksummed) row.VerifyChecksums(0, kNumFrameColumns - 1, kNumFrameColumns - 1);
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

// TruthColumns from column `first`; nullopt when the frame has no ground truth.
std::optional<GroundTruthRecord> DecodeTruth(const Row& row, int first, std::size_t num_peaks,
                                             bool checksummed) {
  if (row.IsNull(first)) return std::nullopt;
  if (checksummed) row.VerifyChecksums(first, 10, first + 10);
  GroundTruthRecord truth;
  truth.T_W_C = row.Pose(first + 1);
  truth.points_W = row.Items<Eigen::Vector3d, double>(first + 8, std::int64_t(num_peaks));
  truth.object_ids = row.Items<std::int32_t>(first + 9, std::int64_t(num_peaks));
  return truth;
}

// What is missing from a SQLite file shorter than its header says it is (an interrupted copy
// or transfer), or nullopt. The header's page count is only valid when its "version-valid-for"
// number equals the change counter (SQLite's file format, section 1.3); a file too short to
// hold a header is left to SQLite to refuse.
std::optional<std::string> Truncation(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char h[100];
  if (!in.read(reinterpret_cast<char*>(h), sizeof(h))) return std::nullopt;
  const auto be32 = [&h](int at) {
    return (std::uint32_t(h[at]) << 24) | (std::uint32_t(h[at + 1]) << 16) |
           (std::uint32_t(h[at + 2]) << 8) | std::uint32_t(h[at + 3]);
  };
  const std::uint32_t raw_page = (std::uint32_t(h[16]) << 8) | h[17];
  const std::uint64_t page_bytes = raw_page == 1 ? 65536 : raw_page;
  const std::uint64_t pages = be32(28);
  if (be32(92) != be32(24) || pages == 0 || page_bytes < 512) return std::nullopt;
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec || size >= pages * page_bytes) return std::nullopt;
  return "truncated: " + std::to_string(size) + " bytes of the " +
         std::to_string(pages * page_bytes) + " its header gives (" +
         std::to_string(pages - size / page_bytes) + " of " + std::to_string(pages) +
         " pages missing)";
}

// Whether a write-ahead log beside the file holds frames (more than its 32-byte header): pages
// SQLite reads from there, not from the file, until a checkpoint copies them over.
bool WalHoldsFrames(const fs::path& path) {
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path.string() + "-wal", ec);
  return !ec && size > 32;
}

}  // namespace

struct DiveLogReader::Impl {
  fs::path path;
  std::string name;  // "dive log '<path>'", the start of every error message
  sqlite::Db db;
  DiveLogHeader header;
  Statement frame_by_index, truth_by_index, last_index, mount, navigation;

  bool checksummed() const { return header.schema_version >= kFirstChecksummedVersion; }

  // The header's columns in the order of kHeaderChecksumColumns, then the checksums.
  Statement SelectHeader() const {
    return Prepare(std::string("SELECT ") + kHeaderChecksumColumns + ", " +
                       Checksums("header", checksummed()) + " FROM header",
                   0);
  }

  // Prepared at open, so that a table or column missing from the file shows there.
  Statement Prepare(const std::string& sql, unsigned flags = SQLITE_PREPARE_PERSISTENT) const {
    return sqlite::Prepare(
        db.get(), sql, flags, name,
        "does not match schema version " + std::to_string(header.schema_version));
  }

  // The names of the file's tables. The first read of the file: where a file that is not
  // SQLite shows.
  std::set<std::string> Tables() const {
    auto fail = [&] {
      if (sqlite3_errcode(db.get()) == SQLITE_NOTADB) {
        throw Error(name + " is not a SQLite database");
      }
      // Looked at only once SQLite has failed: a raw read of a log whose writer is checkpointing
      // can see the header's new page count before the pages that extend the file.
      if (const std::optional<std::string> truncation = Truncation(path)) {
        throw Error(name + " is " + *truncation +
                    "; `uwscan log salvage` copies what it holds into a new log");
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
    if (header.schema_version < kOldestDiveLogSchemaVersion ||
        header.schema_version > kDiveLogSchemaVersion) {
      throw Error(name + " has schema version " + std::to_string(header.schema_version) +
                  ", this uwscan reads " + std::to_string(kOldestDiveLogSchemaVersion) + " to " +
                  std::to_string(kDiveLogSchemaVersion));
    }
  }

  void ReadHeader() {
    Statement head = SelectHeader();
    int rc = sqlite3_step(head.get());
    if (rc == SQLITE_DONE) throw Error(name + ": table header is empty");
    if (rc != SQLITE_ROW) sqlite::Fail(name, "cannot read the header", db.get());
    const Row row(head.get(), name, "table header");
    if (checksummed()) row.VerifyChecksums(0, kNumHeaderChecksumColumns, kNumHeaderChecksumColumns);
    // Parsed here, once: the rest of uwscan takes the scanner and the pattern as values.
    const std::string kind = row.Text(0);
    header.scanner = scanner::ParseScanner(row.Text(1), name + ", header.scanner_yaml");
    header.scan_pattern =
        scanner::ParseScanPattern(row.Text(2), name + ", header.scan_pattern_yaml");
    if (kind != scanner::ToString(header.scanner.kind()) ||
        header.scan_pattern.kind != header.scanner.kind()) {
      throw Error(name + ": header.scanner_kind '" + kind + "', the scanner (" +
                  scanner::ToString(header.scanner.kind()) + ") and the scan pattern (" +
                  scanner::ToString(header.scan_pattern.kind) + ") disagree");
    }
    header.scene_yaml = row.Text(3);
    header.created_utc = row.Text(4);
    header.producer = row.Text(5);
    rc = sqlite3_step(head.get());
    if (rc == SQLITE_ROW) throw Error(name + ": table header has more than one row");
    if (rc != SQLITE_DONE) sqlite::Fail(name, "cannot read the header", db.get());
  }

  // Version 2 on: the navigation's noise model, when the writer had one.
  void ReadNavigationNoise() {
    Statement select =
        Prepare(std::string("SELECT ") + kNoiseChecksumColumns + ", " +
                    Checksums("navigation_noise", checksummed()) + " FROM navigation_noise",
                0);
    const int rc = sqlite3_step(select.get());
    if (rc == SQLITE_DONE) return;
    if (rc != SQLITE_ROW) sqlite::Fail(name, "cannot read the navigation noise", db.get());
    const Row row(select.get(), name, "table navigation_noise");
    if (checksummed()) row.VerifyChecksums(0, kNumNoiseChecksumColumns, kNumNoiseChecksumColumns);
    NavigationNoise noise;
    noise.position_walk_m_per_sqrt_s = row.Real(0);
    noise.heading_walk_rad_per_sqrt_s = row.Real(1);
    noise.speed_scale_sigma = row.Real(2);
    noise.heading_bias_sigma_rad = row.Real(3);
    noise.depth_sigma_m = row.Real(4);
    noise.roll_pitch_sigma_rad = row.Real(5);
    try {
      noise.Check();
    } catch (const Error& e) {
      throw Error(name + ": table navigation_noise: " + e.what());
    }
    header.navigation_noise = noise;
  }

  [[noreturn]] void NoSuchFrame(std::int64_t index, std::int64_t count) const {
    throw Error(name + " has no " + FrameName(index) + " (it holds " + std::to_string(count) +
                " frames)");
  }
};

bool IsSqliteFile(const std::filesystem::path& path) {
  if (!IsRegularFile(path)) return false;  // a pipe with no writer would block the read
  std::ifstream in(path, std::ios::binary);
  char magic[16] = {};
  in.read(magic, sizeof(magic));
  // The header's 16 bytes are the text and its terminating NUL.
  return in.gcount() == 16 && std::memcmp(magic, "SQLite format 3", 16) == 0;
}

DiveLogReader::DiveLogReader(const std::filesystem::path& path, DiveLogOpening opening)
    : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.path = path;
  r.name = LogName(path);
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(r.name + ": no such file");
  if (!fs::is_regular_file(path, ec)) throw Error(r.name + ": not a regular file");

  r.db = sqlite::Open(path, SQLITE_OPEN_READONLY, kBusyTimeout_ms, r.name);
  // Checks each b-tree cell against its page as it is read: damage fails cleanly and early.
  sqlite::Exec(r.db.get(), "PRAGMA cell_size_check = ON", r.name, "cannot enable cell checks");
  if (opening == DiveLogOpening::kDamaged) {
    // SQLite refuses a file shorter than its header's page count unless the schema is writable;
    // then it reads the pages there are (the connection stays read-only: nothing is written).
    sqlite::Exec(r.db.get(), "PRAGMA writable_schema = ON", r.name, "cannot read a damaged file");
  }

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
  if (r.header.schema_version >= 2 && !tables.contains("navigation_noise")) {
    throw Error(r.name + " has no table 'navigation_noise' (schema version " +
                std::to_string(r.header.schema_version) + " has it)");
  }
  r.ReadHeader();
  if (r.header.schema_version >= 2) r.ReadNavigationNoise();

  const bool checksummed = r.checksummed();
  r.frame_by_index =
      r.Prepare("SELECT " + FrameColumns(checksummed) + " FROM frames f WHERE f.frame_index = ?");
  // length() reads a blob's size from the record header, without reading the blob.
  r.truth_by_index = r.Prepare("SELECT length(f.peaks_px), " + TruthColumns(checksummed) +
                               " FROM frames f LEFT JOIN ground_truth g"
                               " ON g.frame_index = f.frame_index WHERE f.frame_index = ?");
  // The largest primary key is found without a scan; indices run from 0 without gaps.
  r.last_index = r.Prepare("SELECT max(frame_index) FROM frames");
  r.mount = r.SelectHeader();
  r.navigation = r.Prepare(
      "SELECT nav_id, time_s, T_W_V_tx, T_W_V_ty, T_W_V_tz, T_W_V_qx, T_W_V_qy, T_W_V_qz, "
      "T_W_V_qw, " +
      Checksums("navigation", checksummed) + " FROM navigation ORDER BY time_s, nav_id");
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
  if (r.checksummed()) row.VerifyChecksums(0, kNumHeaderChecksumColumns, kNumHeaderChecksumColumns);
  constexpr int kMount = 6;  // T_V_C_tx in kHeaderChecksumColumns
  for (int i = kMount; i < kMount + 7; ++i) {
    if (!row.IsNull(i)) return row.Pose(kMount);
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
    if (rc == SQLITE_ROW)
      return DecodeFrame(Row(s, r.name, FrameName(index)), index, r.checksummed());
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
      return DecodeTruth(row, 1, std::size_t(peak_bytes) / sizeof(Eigen::Vector2d),
                         r.checksummed());
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
  const bool checksummed = r.checksummed();
  const std::string sql =
      with_truth ? "SELECT " + FrameColumns(checksummed) + ", " + TruthColumns(checksummed) +
                       " FROM frames f LEFT JOIN ground_truth g USING (frame_index)"
                       " ORDER BY f.frame_index"
                 : "SELECT " + FrameColumns(checksummed) + " FROM frames f ORDER BY f.frame_index";
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
    const FrameRecord frame = DecodeFrame(row, index, checksummed);
    if (with_truth) {
      const std::optional<GroundTruthRecord> truth =
          DecodeTruth(row, kNumFrameColumns, frame.peaks_px.size(), checksummed);
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
    if (r.checksummed()) row.VerifyChecksums(1, 8, 9);
    samples.push_back({row.Real(1), row.Pose(2)});
  }
  if (rc != SQLITE_DONE) sqlite::Fail(r.name, "cannot read the navigation", r.db.get());
  return samples;
}

namespace {

// Runs a read-only statement, handing each row's column 0 as an integer to `row`; returns
// SQLite's message when stepping fails half-way ("" when it ends cleanly).
std::string ForEachInteger(sqlite3* db, const std::string& sql,
                           const std::function<void(std::int64_t)>& row) {
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &raw, nullptr) != SQLITE_OK)
    return sqlite3_errmsg(db);
  const Statement statement(raw);
  int rc;
  while ((rc = sqlite3_step(raw)) == SQLITE_ROW) row(sqlite3_column_int64(raw, 0));
  return rc == SQLITE_DONE ? std::string() : std::string(sqlite3_errmsg(db));
}

}  // namespace

namespace {

// SQLite's own check of the file's structure (pages, b-trees), without the index cross-checks:
// what it found wrong ("ok" left out).
std::vector<std::string> QuickCheck(sqlite3* db) {
  std::vector<std::string> problems;
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(db, "PRAGMA quick_check(20)", -1, &raw, nullptr) != SQLITE_OK) {
    problems.push_back(sqlite3_errmsg(db));
  }
  const Statement statement(raw);
  int rc = SQLITE_DONE;
  while (raw && (rc = sqlite3_step(raw)) == SQLITE_ROW) {
    const auto* text = reinterpret_cast<const char*>(sqlite3_column_text(raw, 0));
    const std::string line = text ? text : "?";
    if (line != "ok") problems.push_back(line);
  }
  if (raw && rc != SQLITE_DONE) problems.push_back(sqlite3_errmsg(db));
  return problems;
}

// Frames one by one through the primary key, so that a damaged page costs only its rows. A
// frame is worth keeping without its ground truth: a real dive has none.
void CheckFrames(const DiveLogReader& log, sqlite3* db, const std::string& name,
                 const std::function<void(const FrameRecord&, const GroundTruthRecord*)>& frame,
                 const std::function<void(double)>& progress, DiveLogCheck& check) {
  std::vector<std::int64_t> indices;
  const std::string listing =
      ForEachInteger(db, "SELECT frame_index FROM frames ORDER BY frame_index",
                     [&](std::int64_t index) { indices.push_back(index); });
  if (!listing.empty()) {
    check.damage.push_back({"file", -1,
                            name + ": cannot list the frames past " +
                                std::to_string(indices.size()) + " (" + listing + ")"});
  }
  check.frames = static_cast<std::int64_t>(indices.size());
  std::int64_t expected = 0;
  for (std::size_t done = 0; done < indices.size(); ++done) {
    const std::int64_t index = indices[done];
    if (progress) progress(static_cast<double>(done) / static_cast<double>(indices.size()));
    for (; expected < index; ++expected) {
      check.damage.push_back(
          {"frames", expected, name + ": " + FrameName(expected) + " is missing"});
    }
    expected = index + 1;
    std::optional<FrameRecord> record;
    try {
      record = log.ReadFrame(index);
    } catch (const Error& e) {
      check.damage.push_back({"frames", index, e.what()});
      continue;
    }
    std::optional<GroundTruthRecord> truth;
    try {
      truth = log.ReadGroundTruth(index);
    } catch (const Error& e) {
      check.damage.push_back({"ground_truth", index, e.what()});
      ++check.frames_with_damaged_truth;
    }
    ++check.frames_intact;
    if (frame) frame(*record, truth ? &*truth : nullptr);
  }
}

// Navigation row by row, in the order it was appended, from `s` (nav_id, time, pose, checksums).
void CheckNavigation(sqlite3_stmt* s, sqlite3* db, const std::string& name, bool checksummed,
                     const std::function<void(const NavigationRecord&)>& navigation,
                     DiveLogCheck& check) {
  int rc;
  while ((rc = sqlite3_step(s)) == SQLITE_ROW) {
    ++check.navigation;
    const std::int64_t nav_id = sqlite3_column_int64(s, 0);
    try {
      const Row row(s, name, "navigation sample " + std::to_string(nav_id));
      if (checksummed) row.VerifyChecksums(1, 8, 9);
      const NavigationRecord record{row.Real(1), row.Pose(2)};
      ++check.navigation_intact;
      if (navigation) navigation(record);
    } catch (const Error& e) {
      check.damage.push_back({"navigation", nav_id, e.what()});
    }
  }
  if (rc != SQLITE_DONE) {
    check.damage.push_back({"file", -1,
                            name + ": cannot read the navigation past " +
                                std::to_string(check.navigation) + " samples (" +
                                sqlite3_errmsg(db) + ")"});
  }
}

}  // namespace

DiveLogCheck DiveLogReader::Check(
    const std::function<void(const FrameRecord&, const GroundTruthRecord*)>& frame,
    const std::function<void(const NavigationRecord&)>& navigation,
    const std::function<void(double)>& progress) const {
  const Impl& r = *impl_;
  DiveLogCheck check;
  check.schema_version = r.header.schema_version;
  check.checksummed = r.checksummed();
  // A writer killed while checkpointing leaves the header's new page count ahead of the pages it
  // had copied, the rest still in the WAL: with frames there, the file's size says nothing, and
  // the quick check (which reads every page through the WAL) judges it.
  if (const std::optional<std::string> truncation = Truncation(r.path);
      truncation && !WalHoldsFrames(r.path)) {
    check.integrity.push_back("the file is " + *truncation);
  }
  for (std::string& problem : QuickCheck(r.db.get())) check.integrity.push_back(std::move(problem));
  try {
    vehicle_mount();
  } catch (const Error& e) {
    check.damage.push_back({"header", -1, e.what()});
  }
  CheckFrames(*this, r.db.get(), r.name, frame, progress, check);
  const Statement statement = r.Prepare(
      "SELECT nav_id, time_s, T_W_V_tx, T_W_V_ty, T_W_V_tz, T_W_V_qx, T_W_V_qy, T_W_V_qz, "
      "T_W_V_qw, " +
          Checksums("navigation", r.checksummed()) + " FROM navigation ORDER BY nav_id",
      0);
  CheckNavigation(statement.get(), r.db.get(), r.name, r.checksummed(), navigation, check);
  if (progress) progress(1.0);
  return check;
}

const std::filesystem::path& DiveLogReader::path() const { return impl_->path; }

}  // namespace uwscan::mapping
