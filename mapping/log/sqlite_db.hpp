#pragma once

// A thin layer over SQLite for uwscan's files: owned handles, errors that name the file, and
// typed, checked reading of result columns (numbers, text, little-endian blobs, poses).
// Included only by the .cpp files of uwscan::mapping: public headers keep sqlite3.h out.

#include <sqlite3.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace uwscan::mapping::sqlite {

struct DbCloser {
  void operator()(sqlite3* db) const { sqlite3_close_v2(db); }
};
struct StatementFinalizer {
  void operator()(sqlite3_stmt* statement) const { sqlite3_finalize(statement); }
};
using Db = std::unique_ptr<sqlite3, DbCloser>;
using Statement = std::unique_ptr<sqlite3_stmt, StatementFinalizer>;

// Every function here starts its error messages with `name`, which names the file
// ("dive log '/data/dive.uwlog'"), and ends them with SQLite's own reason in parentheses.

// Throws uwscan::Error: "<name>: <what> (<SQLite's message>)".
[[noreturn]] void Fail(const std::string& name, const std::string& what, sqlite3* db);

// Opens a connection for use by one thread at a time (SQLite's mutexes are off) that waits up
// to `busy_timeout_ms` for another connection's lock before failing.
Db Open(const std::filesystem::path& path, int flags, int busy_timeout_ms, const std::string& name);

// Throws "<name>: <what_on_failure> (...)" when the SQL does not compile (a missing table or
// column shows here).
Statement Prepare(sqlite3* db, const std::string& sql, unsigned flags, const std::string& name,
                  const std::string& what_on_failure);

// Runs SQL without results.
void Exec(sqlite3* db, const char* sql, const std::string& name, const std::string& what);

// Steps a statement that returns no rows to completion, then resets it.
void StepDone(sqlite3* db, sqlite3_stmt* statement, const std::string& name,
              const std::string& what);

// Resets a cached statement on scope exit, so that it ends its read snapshot and forgets its
// bound pointers even when decoding throws half-way.
class ResetOnExit {
 public:
  explicit ResetOnExit(sqlite3_stmt* statement) : statement_(statement) {}
  ~ResetOnExit() {
    sqlite3_reset(statement_);
    sqlite3_clear_bindings(statement_);
  }
  ResetOnExit(const ResetOnExit&) = delete;
  ResetOnExit& operator=(const ResetOnExit&) = delete;

 private:
  sqlite3_stmt* statement_;
};

// ---- Blobs hold little-endian numbers ----

// The bytes of `count` numbers in little-endian order. On a little-endian host (every target
// uwscan has) that is the array itself, bound without a copy; elsewhere a swapped copy in
// `scratch`.
template <typename T>
const void* LittleEndianBytes(const T* values, std::size_t count,
                              [[maybe_unused]] std::vector<std::uint8_t>& scratch) {
  if constexpr (std::endian::native == std::endian::little) {
    return values;
  } else {
    scratch.resize(count * sizeof(T));
    for (std::size_t i = 0; i < count; ++i) {
      const auto* bytes = reinterpret_cast<const std::uint8_t*>(values + i);
      std::reverse_copy(bytes, bytes + sizeof(T), scratch.data() + i * sizeof(T));
    }
    return scratch.data();
  }
}

template <typename T>
void FromLittleEndian(const void* blob, std::size_t count, T* values) {
  if (count == 0) return;
  std::memcpy(values, blob, count * sizeof(T));
  if constexpr (std::endian::native != std::endian::little) {
    for (std::size_t i = 0; i < count; ++i) {
      auto* bytes = reinterpret_cast<std::uint8_t*>(values + i);
      std::reverse(bytes, bytes + sizeof(T));
    }
  }
}

// Binds `bytes` bytes as a blob that must stay alive until the statement is reset. Zero bytes
// bind an empty blob (sqlite3_bind_blob would bind NULL for the null pointer an empty vector
// may give). Returns SQLite's result code.
int BindBlob(sqlite3_stmt* statement, int column, const void* data, std::size_t bytes);

// ---- Poses: 7 REAL columns tx ty tz qx qy qz qw ----

// T's translation and its rotation as the unit quaternion with qw >= 0: tx ty tz qx qy qz qw.
// T's rotation must be orthonormal (checked by the caller).
std::array<double, 7> PoseColumns(const Eigen::Isometry3d& T);
// Binds PoseColumns(T). T's rotation
// must be orthonormal (checked by the caller). Returns SQLite's result code.
int BindPose(sqlite3_stmt* statement, int first_column, const Eigen::Isometry3d& T);

// ---- Reading one result row; every error names the file, the row and the column ----

class Row {
 public:
  // `context` names the row in errors ("frame 12"); the statement must be on a row.
  Row(sqlite3_stmt* statement, const std::string& name, std::string context);

  [[noreturn]] void Corrupt(int column, const std::string& what) const;

  bool IsNull(int column) const;
  std::int64_t Integer(int column) const;  // an INTEGER
  int Int(int column) const;               // an INTEGER within the range of int
  double Real(int column) const;           // a finite number
  std::string Text(int column) const;      // TEXT (may hold any bytes, NUL included)

  // A blob of little-endian Scalars read as Items (Scalar itself or a packed fixed-size Eigen
  // vector of Scalars), checked to hold whole items, exactly `expected_items` unless negative.
  template <typename Item, typename Scalar = Item>
  std::vector<Item> Items(int column, std::int64_t expected_items) const {
    static_assert(sizeof(Item) % sizeof(Scalar) == 0, "an item must be whole scalars");
    const std::size_t bytes = BlobBytes(column, sizeof(Item), expected_items);
    std::vector<Item> items(bytes / sizeof(Item));
    if (!items.empty()) {
      FromLittleEndian(sqlite3_column_blob(statement_, column), bytes / sizeof(Scalar),
                       reinterpret_cast<Scalar*>(items.data()));
    }
    return items;
  }

  // Columns first .. first + 6 as written by BindPose. The quaternion must have unit norm to
  // 1e-6 (it is then normalised exactly).
  Eigen::Isometry3d Pose(int first_column) const;
  // Schema version 3 on: columns first .. first + count - 1 against the per-column checksums in
  // `checksum_column` (mapping/log/row_checksums.hpp). Throws naming the first column that differs.
  void VerifyChecksums(int first, int count, int checksum_column) const;

 private:
  // The blob's size after the checks Items describes.
  std::size_t BlobBytes(int column, std::size_t item_bytes, std::int64_t expected_items) const;

  sqlite3_stmt* statement_;
  const std::string& name_;
  std::string context_;
};

}  // namespace uwscan::mapping::sqlite
