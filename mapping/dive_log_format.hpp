#pragma once

// What the dive log's writer and reader share: the file's schema and constants (documented in
// mapping/README.md) and the names used in messages. Internal to mapping/.

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace uwscan::mapping::dive_log_format {

// The schema of version 2, documented in mapping/README.md (version 1 lacks navigation_noise).
// A later version may add tables and columns; a reader refuses versions it does not know.
inline constexpr const char* kSchemaSql = R"sql(
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
CREATE TABLE navigation_noise (
  id INTEGER PRIMARY KEY CHECK (id = 1),
  position_walk_m_per_sqrt_s REAL NOT NULL, heading_walk_rad_per_sqrt_s REAL NOT NULL,
  speed_scale_sigma REAL NOT NULL, heading_bias_sigma_rad REAL NOT NULL,
  depth_sigma_m REAL NOT NULL, roll_pitch_sigma_rad REAL NOT NULL);
)sql";

// "UWDL": lets `file` and other tools tell a dive log from any other SQLite database.
inline constexpr std::int32_t kApplicationId = 0x5557444C;

// How long a connection waits for another one's lock (a checkpoint, a second writer) before
// failing with "database is locked".
inline constexpr int kBusyTimeout_ms = 5000;

// The file keeps rotations as unit quaternions: a rotation further than this from orthonormal
// is refused rather than silently changed.
inline constexpr double kRigidTolerance = 1e-6;

// Peaks and points are stored as packed doubles.
static_assert(sizeof(Eigen::Vector2d) == 2 * sizeof(double), "peaks must be packed doubles");
static_assert(sizeof(Eigen::Vector3d) == 3 * sizeof(double), "points must be packed doubles");

// "dive log '<path>'", the start of every error message about a log.
std::string LogName(const std::filesystem::path& path);
// "'<path>'".
std::string Quoted(const std::filesystem::path& path);
// "frame <index>".
std::string FrameName(std::int64_t index);

// Mono16 pixels between native and little-endian order (big-endian hosts only).
void SwapBytePairs(std::vector<std::uint8_t>& bytes);

}  // namespace uwscan::mapping::dive_log_format
