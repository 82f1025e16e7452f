#pragma once

// Per-column checksums of a dive log row (schema version 3 on): the writer computes them from
// the values it binds, the reader from the values SQLite returns, so a changed byte anywhere in
// a row names the column it changed. Stored as one BLOB per row: a little-endian uint32 per
// column, in the order the table lists them (mapping/README.md). Internal to mapping/.

#include <sqlite3.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace uwscan::mapping {

// The checksums of one row, built column by column in the table's order.
class RowChecksums {
 public:
  // INTEGER and REAL alike, as the double they equal: SQLite stores an integral REAL as an
  // integer (-0.0 comes back as 0.0), so the stored type of a number is not the writer's.
  void Number(double value);
  void Bytes(const void* data, std::size_t size);  // a BLOB or TEXT
  void Text(const std::string& text) { Bytes(text.data(), text.size()); }
  void Null();
  // Column `column` of the current row of `statement`, by its stored type.
  void Column(sqlite3_stmt* statement, int column);

  // The checksums column's content.
  const std::vector<std::uint8_t>& blob() const { return blob_; }
  std::size_t size() const { return blob_.size() / 4; }

  // The first column (0 = the first one added) whose checksum differs from `stored`, -1 when
  // all agree, size() when `stored` does not hold one checksum per column.
  int FirstMismatch(const void* stored, std::size_t stored_bytes) const;

 private:
  void Add(std::uint32_t checksum);
  std::vector<std::uint8_t> blob_;
};

}  // namespace uwscan::mapping
