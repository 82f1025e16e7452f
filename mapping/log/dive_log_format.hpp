#pragma once

// What the dive log's writer and reader share: the file's schema and constants (documented in
// mapping/README.md) and the names used in messages. Internal to mapping/.

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace uwscan::mapping::dive_log_format {

// The schema of version 3, documented in mapping/README.md (version 1 lacks navigation_noise,
// version 2 the checksums). A later version may add tables and columns; a reader refuses
// versions it does not know. Every `checksums` column holds one little-endian uint32 per column
// of its row, in the order of the k*ChecksumColumns lists below (mapping/log/row_checksums.hpp).
inline constexpr const char* kSchemaSql = R"sql(
CREATE TABLE meta (key TEXT PRIMARY KEY NOT NULL, value NOT NULL);
CREATE TABLE header (
  id INTEGER PRIMARY KEY CHECK (id = 1),
  scanner_kind TEXT NOT NULL, scanner_yaml TEXT NOT NULL, scan_pattern_yaml TEXT NOT NULL,
  scene_yaml TEXT NOT NULL,
  created_utc TEXT NOT NULL, producer TEXT NOT NULL,
  T_V_C_tx REAL, T_V_C_ty REAL, T_V_C_tz REAL,
  T_V_C_qx REAL, T_V_C_qy REAL, T_V_C_qz REAL, T_V_C_qw REAL,
  checksums BLOB NOT NULL);
CREATE TABLE frames (
  frame_index INTEGER PRIMARY KEY, time_s REAL NOT NULL,
  command INTEGER NOT NULL, sweep INTEGER NOT NULL, peaks_px BLOB NOT NULL,
  image_width_px INTEGER, image_height_px INTEGER, image_format INTEGER, image BLOB,
  checksums BLOB NOT NULL);
CREATE TABLE ground_truth (
  frame_index INTEGER PRIMARY KEY REFERENCES frames (frame_index),
  T_W_C_tx REAL NOT NULL, T_W_C_ty REAL NOT NULL, T_W_C_tz REAL NOT NULL,
  T_W_C_qx REAL NOT NULL, T_W_C_qy REAL NOT NULL, T_W_C_qz REAL NOT NULL,
  T_W_C_qw REAL NOT NULL, points_W BLOB NOT NULL, object_ids BLOB NOT NULL,
  checksums BLOB NOT NULL);
CREATE TABLE navigation (
  nav_id INTEGER PRIMARY KEY, time_s REAL NOT NULL,
  T_W_V_tx REAL NOT NULL, T_W_V_ty REAL NOT NULL, T_W_V_tz REAL NOT NULL,
  T_W_V_qx REAL NOT NULL, T_W_V_qy REAL NOT NULL, T_W_V_qz REAL NOT NULL,
  T_W_V_qw REAL NOT NULL, checksums BLOB NOT NULL);
CREATE TABLE navigation_noise (
  id INTEGER PRIMARY KEY CHECK (id = 1),
  position_walk_m_per_sqrt_s REAL NOT NULL, heading_walk_rad_per_sqrt_s REAL NOT NULL,
  speed_scale_sigma REAL NOT NULL, heading_bias_sigma_rad REAL NOT NULL,
  depth_sigma_m REAL NOT NULL, roll_pitch_sigma_rad REAL NOT NULL,
  checksums BLOB NOT NULL);
)sql";

// The first schema version with checksums.
inline constexpr int kFirstChecksummedVersion = 3;

// The columns each row's checksums cover, in order (the navigation's nav_id is SQLite's own
// row number, assigned after the checksums are made; it only orders equal times).
inline constexpr const char* kHeaderChecksumColumns =
    "scanner_kind, scanner_yaml, scan_pattern_yaml, scene_yaml, created_utc, producer, "
    "T_V_C_tx, T_V_C_ty, T_V_C_tz, T_V_C_qx, T_V_C_qy, T_V_C_qz, T_V_C_qw";
inline constexpr int kNumHeaderChecksumColumns = 13;
inline constexpr const char* kNoiseChecksumColumns =
    "position_walk_m_per_sqrt_s, heading_walk_rad_per_sqrt_s, speed_scale_sigma, "
    "heading_bias_sigma_rad, depth_sigma_m, roll_pitch_sigma_rad";
inline constexpr int kNumNoiseChecksumColumns = 6;

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
