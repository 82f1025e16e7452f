#include "mapping/log/row_checksums.hpp"

#include <xxhash.h>

#include <bit>
#include <cstring>

namespace uwscan::mapping {
namespace {

// The seed tells the value's kind apart, so that a number and a blob with the same bytes, or an
// empty blob and NULL, never share a checksum.
enum Kind : XXH64_hash_t { kNumber = 1, kBytes = 3, kNull = 4 };

std::uint32_t Checksum(const void* data, std::size_t size, Kind kind) {
  return static_cast<std::uint32_t>(XXH3_64bits_withSeed(data, size, kind));
}

}  // namespace

void RowChecksums::Add(std::uint32_t checksum) {
  for (int byte = 0; byte < 4; ++byte)
    blob_.push_back(static_cast<std::uint8_t>(checksum >> (8 * byte)));
}

void RowChecksums::Number(double value) {
  // The double's eight bytes in little-endian order, whatever the host.
  std::uint64_t bits = std::bit_cast<std::uint64_t>(value == 0.0 ? 0.0 : value);
  if constexpr (std::endian::native != std::endian::little) bits = __builtin_bswap64(bits);
  Add(Checksum(&bits, sizeof(bits), kNumber));
}

void RowChecksums::Bytes(const void* data, std::size_t size) {
  Add(Checksum(size == 0 ? nullptr : data, size, kBytes));
}

void RowChecksums::Null() { Add(Checksum(nullptr, 0, kNull)); }

void RowChecksums::Column(sqlite3_stmt* statement, int column) {
  switch (sqlite3_column_type(statement, column)) {
    case SQLITE_INTEGER:
      Number(static_cast<double>(sqlite3_column_int64(statement, column)));
      break;
    case SQLITE_FLOAT:
      Number(sqlite3_column_double(statement, column));
      break;
    case SQLITE_NULL:
      Null();
      break;
    default: {  // BLOB or TEXT: the bytes as stored
      const void* data = sqlite3_column_blob(statement, column);
      Bytes(data, static_cast<std::size_t>(sqlite3_column_bytes(statement, column)));
    }
  }
}

int RowChecksums::FirstMismatch(const void* stored, std::size_t stored_bytes) const {
  if (stored == nullptr || stored_bytes != blob_.size()) return static_cast<int>(size());
  const auto* bytes = static_cast<const std::uint8_t*>(stored);
  for (std::size_t column = 0; column < size(); ++column) {
    if (std::memcmp(bytes + 4 * column, blob_.data() + 4 * column, 4) != 0)
      return static_cast<int>(column);
  }
  return -1;
}

}  // namespace uwscan::mapping
