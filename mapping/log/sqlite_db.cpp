#include "mapping/log/sqlite_db.hpp"

#include <array>
#include <cmath>
#include <limits>

#include "mapping/log/row_checksums.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::mapping::sqlite {

void Fail(const std::string& name, const std::string& what, sqlite3* db) {
  throw Error(name + ": " + what + " (" + sqlite3_errmsg(db) + ")");
}

Db Open(const std::filesystem::path& path, int flags, int busy_timeout_ms,
        const std::string& name) {
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(path.c_str(), &raw, flags | SQLITE_OPEN_NOMUTEX, nullptr);
  Db db(raw);  // a handle comes back even on failure, and must be closed
  if (rc != SQLITE_OK) {
    throw Error(name + ": cannot open (" + (raw ? sqlite3_errmsg(raw) : sqlite3_errstr(rc)) + ")");
  }
  sqlite3_busy_timeout(db.get(), busy_timeout_ms);
  return db;
}

Statement Prepare(sqlite3* db, const std::string& sql, unsigned flags, const std::string& name,
                  const std::string& what_on_failure) {
  sqlite3_stmt* raw = nullptr;
  const int rc = sqlite3_prepare_v3(db, sql.c_str(), -1, flags, &raw, nullptr);
  Statement statement(raw);
  if (rc != SQLITE_OK) Fail(name, what_on_failure, db);
  return statement;
}

void Exec(sqlite3* db, const char* sql, const std::string& name, const std::string& what) {
  if (sqlite3_exec(db, sql, nullptr, nullptr, nullptr) != SQLITE_OK) Fail(name, what, db);
}

void StepDone(sqlite3* db, sqlite3_stmt* statement, const std::string& name,
              const std::string& what) {
  ResetOnExit reset(statement);
  if (sqlite3_step(statement) != SQLITE_DONE) Fail(name, what, db);
}

int BindBlob(sqlite3_stmt* statement, int column, const void* data, std::size_t bytes) {
  if (bytes == 0) return sqlite3_bind_zeroblob(statement, column, 0);
  return sqlite3_bind_blob64(statement, column, data, bytes, SQLITE_STATIC);
}

std::array<double, 7> PoseColumns(const Eigen::Isometry3d& T) {
  Eigen::Quaterniond q(Eigen::Matrix3d(T.linear()));
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // always the same one of the two
  const Eigen::Vector3d t = T.translation();
  return {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
}

int BindPose(sqlite3_stmt* statement, int first_column, const Eigen::Isometry3d& T) {
  const std::array<double, 7> columns = PoseColumns(T);
  for (int i = 0; i < 7; ++i) {
    const int rc = sqlite3_bind_double(statement, first_column + i, columns[i]);
    if (rc != SQLITE_OK) return rc;
  }
  return SQLITE_OK;
}

Row::Row(sqlite3_stmt* statement, const std::string& name, std::string context)
    : statement_(statement), name_(name), context_(std::move(context)) {}

void Row::Corrupt(int column, const std::string& what) const {
  const char* column_name = sqlite3_column_name(statement_, column);
  throw Error(name_ + ": " + context_ + ": column " + (column_name ? column_name : "?") + " " +
              what);
}

void Row::VerifyChecksums(int first, int count, int checksum_column) const {
  RowChecksums computed;
  for (int column = first; column < first + count; ++column) computed.Column(statement_, column);
  const int mismatch = computed.FirstMismatch(
      sqlite3_column_blob(statement_, checksum_column),
      static_cast<std::size_t>(sqlite3_column_bytes(statement_, checksum_column)));
  if (mismatch == count) {
    Corrupt(checksum_column, "does not hold " + std::to_string(count) + " checksums (damaged)");
  }
  if (mismatch >= 0) Corrupt(first + mismatch, "does not match its checksum (damaged)");
}

bool Row::IsNull(int column) const {
  return sqlite3_column_type(statement_, column) == SQLITE_NULL;
}

std::int64_t Row::Integer(int column) const {
  if (sqlite3_column_type(statement_, column) != SQLITE_INTEGER) {
    Corrupt(column, "is not an integer");
  }
  return sqlite3_column_int64(statement_, column);
}

int Row::Int(int column) const {
  const std::int64_t value = Integer(column);
  if (value < std::numeric_limits<int>::min() || value > std::numeric_limits<int>::max()) {
    Corrupt(column, "holds " + std::to_string(value) + ", beyond the range of int");
  }
  return static_cast<int>(value);
}

double Row::Real(int column) const {
  // SQLite may store an integral REAL as an integer; it reads back as the same double.
  const int type = sqlite3_column_type(statement_, column);
  if (type != SQLITE_FLOAT && type != SQLITE_INTEGER) Corrupt(column, "is not a number");
  const double value = sqlite3_column_double(statement_, column);
  if (!std::isfinite(value)) Corrupt(column, "is not finite");
  return value;
}

std::string Row::Text(int column) const {
  if (sqlite3_column_type(statement_, column) != SQLITE_TEXT) Corrupt(column, "is not text");
  const auto* text = reinterpret_cast<const char*>(sqlite3_column_text(statement_, column));
  const auto size = static_cast<std::size_t>(sqlite3_column_bytes(statement_, column));
  return text ? std::string(text, size) : std::string();
}

std::size_t Row::BlobBytes(int column, std::size_t item_bytes, std::int64_t expected_items) const {
  if (sqlite3_column_type(statement_, column) != SQLITE_BLOB) Corrupt(column, "is not a blob");
  const auto bytes = static_cast<std::size_t>(sqlite3_column_bytes(statement_, column));
  if (expected_items >= 0 && bytes != static_cast<std::size_t>(expected_items) * item_bytes) {
    Corrupt(column, "holds " + std::to_string(bytes) + " bytes, expected " +
                        std::to_string(static_cast<std::size_t>(expected_items) * item_bytes));
  }
  if (bytes % item_bytes != 0) {
    Corrupt(column, "holds " + std::to_string(bytes) + " bytes, not a multiple of " +
                        std::to_string(item_bytes));
  }
  return bytes;
}

Eigen::Isometry3d Row::Pose(int first_column) const {
  std::array<double, 7> c;
  for (int i = 0; i < 7; ++i) c[i] = Real(first_column + i);
  const Eigen::Quaterniond q(c[6], c[3], c[4], c[5]);
  if (std::abs(q.norm() - 1.0) > 1e-6) {
    Corrupt(first_column + 3, "(with the next three) holds a quaternion of norm " +
                                  std::to_string(q.norm()) + ", expected 1");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(c[0], c[1], c[2]);
  return T;
}

}  // namespace uwscan::mapping::sqlite
