#include "perception/cloud/cloud_io.hpp"

#include <pcl/PCLPointCloud2.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "perception/cloud/pcd_reader.hpp"
#include "scanner/common/atomic_file.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"
#include "scanner/common/ply_reader.hpp"

namespace uwscan::perception {
namespace {

namespace fs = std::filesystem;

// Beyond this, coordinates are written as float64: float32 rounding stays under 0.5 um here,
// below the scanner's accuracy (uwscan keeps geometry in double; files must not undo it).
constexpr double kMaxFloat32Coordinate_m = 10.0;

enum class Format { kPcd, kPly, kXyz };

std::optional<Format> FormatOf(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".pcd") return Format::kPcd;
  if (ext == ".ply") return Format::kPly;
  if (ext == ".xyz") return Format::kXyz;
  return std::nullopt;
}

std::string FormatName(Format format) {
  return format == Format::kPcd ? "PCD" : format == Format::kPly ? "PLY" : "XYZ";
}

// Why a file with an extension ReadCloud does not take is not read: a mesh format named as such.
std::string NotACloudFormat(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  if (ext == ".OBJ" || ext == ".OFF" || ext == ".STL")
    return "an " + ext.substr(1) + " file is a mesh, not a point cloud";
  if (ext.empty()) return "no extension to tell its format by";
  return "unknown extension " + ext.substr(1);
}

// Absolute points (and normals and intensities, when the file has them) as read, before any
// filtering.
struct RawCloud {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;
  std::vector<double> intensity;
  std::optional<Eigen::Isometry3d> T_file_sensor;
  std::string viewpoint_error;
};

// One value of a binary point record, as double.
double FieldValue(const std::uint8_t* point, const pcl::PCLPointField& field) {
  const std::uint8_t* at = point + field.offset;
  auto get = [at](auto value) {
    std::memcpy(&value, at, sizeof(value));
    return static_cast<double>(value);
  };
  switch (field.datatype) {
    case pcl::PCLPointField::INT8:
      return get(std::int8_t{});
    case pcl::PCLPointField::UINT8:
      return get(std::uint8_t{});
    case pcl::PCLPointField::INT16:
      return get(std::int16_t{});
    case pcl::PCLPointField::UINT16:
      return get(std::uint16_t{});
    case pcl::PCLPointField::INT32:
      return get(std::int32_t{});
    case pcl::PCLPointField::UINT32:
      return get(std::uint32_t{});
    case pcl::PCLPointField::FLOAT32:
      return get(float{});
    case pcl::PCLPointField::FLOAT64:
      return get(double{});
    default:
      return std::nan("");
  }
}

bool IsXyzSeparator(char c) { return std::isspace(static_cast<unsigned char>(c)) || c == ','; }

// The numbers on one line of an XYZ file into `numbers` (its buffer kept from line to line),
// separated by white space or commas, up to a '#' that starts a comment; throws naming the line
// when a word is not a number.
void XyzNumbers(const std::string& line, std::size_t line_number, const fs::path& path,
                std::vector<double>& numbers) {
  numbers.clear();
  const char* p = line.data();
  const char* end = p + std::min(line.size(), line.find('#'));
  auto skip_separators = [&] {
    while (p < end && IsXyzSeparator(*p)) ++p;
  };
  for (skip_separators(); p < end; skip_separators()) {
    if (*p == '+') ++p;  // from_chars takes no leading '+'
    double value = 0.0;
    const std::from_chars_result parsed = std::from_chars(p, end, value);
    const bool separated = parsed.ptr == end || IsXyzSeparator(*parsed.ptr);
    if (parsed.ec != std::errc() || parsed.ptr == p || !separated) {
      throw Error(
          "ReadCloud: " + QuotedPath(path) + " (read as XYZ) line " + std::to_string(line_number) +
          ": expected numbers x y z (and as many more as "
          "the first point's line has), got '" +
          line.substr(0, std::min<std::size_t>(80, line.find_last_not_of("\r\n") + 1)) + "'");
    }
    numbers.push_back(value);
    p = parsed.ptr;
  }
}

// An XYZ file: a point per line, x y z first, then as many further columns (colour, normal,
// intensity) as the first point's line has, which every line must have (a line with others is
// damage, as a line cut short); '#' starts a comment; lines without numbers are skipped.
RawCloud ReadXyz(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw Error("ReadCloud: cannot open " + QuotedPath(path) + " (read as XYZ)");
  RawCloud raw;
  std::string line;
  std::size_t columns = 0, first_line = 0;
  std::vector<double> numbers;
  for (std::size_t line_number = 1; std::getline(in, line); ++line_number) {
    XyzNumbers(line, line_number, path, numbers);
    if (numbers.empty()) continue;  // blank, or only a comment
    if (columns == 0) columns = numbers.size(), first_line = line_number;
    if (numbers.size() < 3 || numbers.size() != columns) {
      throw Error("ReadCloud: " + QuotedPath(path) + " (read as XYZ) line " +
                  std::to_string(line_number) + ": " + std::to_string(numbers.size()) +
                  " columns where " +
                  (numbers.size() < 3
                       ? std::string("x y z need 3")
                       : "line " + std::to_string(first_line) + " has " + std::to_string(columns)));
    }
    raw.points.emplace_back(numbers[0], numbers[1], numbers[2]);
  }
  if (in.bad())
    throw Error("ReadCloud: error while reading " + QuotedPath(path) + " (read as XYZ)");
  return raw;
}

pcl::PCLPointCloud2 ToBlob(const PointCloud& cloud, Format format) {
  double max_abs = 0.0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    max_abs = std::max(max_abs, cloud.Point(i).cwiseAbs().maxCoeff());
  }
  const bool doubles = max_abs >= kMaxFloat32Coordinate_m;
  const std::uint8_t xyz_type = doubles ? pcl::PCLPointField::FLOAT64 : pcl::PCLPointField::FLOAT32;
  const std::uint32_t xyz_size = doubles ? 8 : 4;

  pcl::PCLPointCloud2 blob;
  auto add_field = [&blob](const char* name, std::uint8_t type, std::uint32_t size) {
    pcl::PCLPointField field;
    field.name = name;
    field.offset = blob.point_step;
    field.datatype = type;
    field.count = 1;
    blob.fields.push_back(field);
    blob.point_step += size;
  };
  add_field("x", xyz_type, xyz_size);
  add_field("y", xyz_type, xyz_size);
  add_field("z", xyz_type, xyz_size);
  const bool normals = cloud.has_normals();
  if (normals) {
    const bool ply = format == Format::kPly;
    add_field(ply ? "nx" : "normal_x", pcl::PCLPointField::FLOAT32, 4);
    add_field(ply ? "ny" : "normal_y", pcl::PCLPointField::FLOAT32, 4);
    add_field(ply ? "nz" : "normal_z", pcl::PCLPointField::FLOAT32, 4);
  }
  const bool intensity = cloud.has_intensity();
  const std::uint32_t intensity_offset = blob.point_step;
  if (intensity) add_field("intensity", pcl::PCLPointField::FLOAT32, 4);
  blob.width = static_cast<std::uint32_t>(cloud.size());
  blob.height = 1;
  blob.is_dense = true;
  blob.row_step = blob.point_step * blob.width;
  blob.data.resize(blob.row_step);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    std::uint8_t* at = blob.data.data() + i * blob.point_step;
    const Eigen::Vector3d p = cloud.Point(i);
    for (int a = 0; a < 3; ++a) {
      if (doubles) {
        std::memcpy(at + 8 * a, &p[a], 8);
      } else {
        const float value = static_cast<float>(p[a]);
        std::memcpy(at + 4 * a, &value, 4);
      }
    }
    if (normals) std::memcpy(at + 3 * xyz_size, cloud.normals[i].data(), 12);
    if (intensity) std::memcpy(at + intensity_offset, &cloud.intensity[i], 4);
  }
  return blob;
}

// PLY written directly (PCL 1.13's PLYWriter ignores the ASCII precision, printing 6 digits):
// one vertex element with the blob's fields, in the host's byte order when binary.
bool WritePly(const fs::path& path, const pcl::PCLPointCloud2& blob, bool binary) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return false;
  const char* format = !binary                                      ? "ascii"
                       : std::endian::native == std::endian::little ? "binary_little_endian"
                                                                    : "binary_big_endian";
  out << "ply\nformat " << format << " 1.0\ncomment uwscan: absolute coordinates in metres\n"
      << "element vertex " << blob.width * blob.height << "\n";
  for (const pcl::PCLPointField& field : blob.fields) {
    out << "property " << (field.datatype == pcl::PCLPointField::FLOAT64 ? "double" : "float")
        << " " << field.name << "\n";
  }
  out << "end_header\n";
  if (binary) {
    out.write(reinterpret_cast<const char*>(blob.data.data()),
              static_cast<std::streamsize>(blob.data.size()));
  } else {
    for (std::size_t i = 0; i < std::size_t{blob.width} * blob.height; ++i) {
      const std::uint8_t* point = blob.data.data() + i * blob.point_step;
      for (std::size_t f = 0; f < blob.fields.size(); ++f) {
        // Round-trip digits: 17 for double, 9 for float.
        out.precision(blob.fields[f].datatype == pcl::PCLPointField::FLOAT64 ? 17 : 9);
        out << (f ? " " : "") << FieldValue(point, blob.fields[f]);
      }
      out << "\n";
    }
  }
  out.close();
  return static_cast<bool>(out);
}

}  // namespace

PointCloud ReadCloud(const std::filesystem::path& path, CloudReadStats* stats) {
  const std::optional<Format> format = FormatOf(path);
  if (!format) {
    throw Error("ReadCloud: " + QuotedPath(path) + ": " + NotACloudFormat(path) +
                " (expected a point cloud: .pcd, .ply or .xyz)");
  }
  RequireRegularFile(path, "ReadCloud: " + QuotedPath(path));

  RawCloud raw;
  if (*format == Format::kXyz) {
    raw = ReadXyz(path);
  } else if (*format == Format::kPly) {
    // uwscan's bounded readers (PCL 1.13's abort on some broken headers and print on bad files).
    scanner::PlyContent ply = scanner::ReadPly(path, /*faces=*/false);
    raw.points = std::move(ply.vertices);
    raw.normals = std::move(ply.normals);
    raw.intensity = std::move(ply.intensity);
  } else {
    PcdContent pcd = ReadPcd(path);
    raw.points = std::move(pcd.points);
    raw.normals = std::move(pcd.normals);
    raw.intensity = std::move(pcd.intensity);
    raw.T_file_sensor = pcd.T_file_sensor;
    raw.viewpoint_error = pcd.viewpoint_error;
  }

  CloudReadStats local;
  local.num_in_file = raw.points.size();
  local.has_normals = !raw.normals.empty();
  local.T_file_sensor = raw.T_file_sensor;
  local.viewpoint_error = raw.viewpoint_error;
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3f> normals;
  std::vector<float> intensity;
  points.reserve(raw.points.size());
  for (std::size_t i = 0; i < raw.points.size(); ++i) {
    // A normal must be a direction: non-finite or (near) zero-length ones drop their point;
    // the others are made exactly unit, as PointCloud requires.
    const bool usable =
        raw.points[i].allFinite() &&
        (raw.normals.empty() || (raw.normals[i].allFinite() && raw.normals[i].norm() > 1e-6));
    if (!usable) continue;
    if (stats) local.rows.push_back(i);
    points.push_back(raw.points[i]);
    if (local.has_normals) normals.push_back(raw.normals[i].normalized().cast<float>());
    if (!raw.intensity.empty()) intensity.push_back(static_cast<float>(raw.intensity[i]));
  }
  local.num_dropped_non_finite = raw.points.size() - points.size();
  if (points.empty()) {
    const std::string as = " (read as " + FormatName(*format) + ")";
    if (local.num_in_file == 0)
      throw Error("ReadCloud: " + QuotedPath(path) + as + ": no point in it");
    throw Error("ReadCloud: " + QuotedPath(path) + as + " holds no finite point (" +
                std::to_string(local.num_in_file) + " in the file, " +
                std::to_string(local.num_dropped_non_finite) +
                " dropped as NaN or infinite, or with a normal that is not a direction)");
  }
  PointCloud cloud = MakeCloud(points);
  cloud.normals = std::move(normals);
  cloud.intensity = std::move(intensity);
  if (stats) *stats = std::move(local);
  return cloud;
}

void WriteCloud(const std::filesystem::path& path, const PointCloud& cloud, bool binary,
                const std::optional<Eigen::Isometry3d>& T_file_sensor) {
  const std::optional<Format> format = FormatOf(path);
  if (!format || *format == Format::kXyz) {
    throw Error("WriteCloud: " + QuotedPath(path) +
                ": unsupported extension (expected .ply or .pcd)");
  }
  if (T_file_sensor && *format != Format::kPcd) {
    throw Error("WriteCloud: " + QuotedPath(path) + ": a sensor pose can only be written to a PCD");
  }
  const Eigen::Isometry3d T = T_file_sensor.value_or(Eigen::Isometry3d::Identity());
  if (!T.matrix().allFinite())
    throw Error("WriteCloud: " + QuotedPath(path) + ": sensor pose not finite");
  const Eigen::Vector4f origin(static_cast<float>(T.translation().x()),
                               static_cast<float>(T.translation().y()),
                               static_cast<float>(T.translation().z()), 0.0f);
  const Eigen::Quaternionf orientation(Eigen::Quaterniond(T.linear()).normalized().cast<float>());
  RequireValidCloud(cloud, "WriteCloud " + QuotedPath(path), 1);
  const pcl::PCLPointCloud2 blob = ToBlob(cloud, *format);
  const bool doubles =
      !blob.fields.empty() && blob.fields.front().datatype == pcl::PCLPointField::FLOAT64;
  const int precision = doubles ? 17 : 9;  // round-trip digits

  const fs::path temporary = TemporaryBeside(path);
  int status = -1;
  std::string reason;
  errno = 0;  // what the failing write leaves here (no space left, file too large) is the reason
  try {
    if (*format == Format::kPcd) {
      pcl::PCDWriter writer;
      status = binary ? writer.writeBinary(temporary.string(), blob, origin, orientation)
                      : writer.writeASCII(temporary.string(), blob, origin, orientation, precision);
    } else {
      status = WritePly(temporary, blob, binary) ? 0 : -1;
    }
  } catch (const std::exception& e) {
    reason = std::string(" (") + e.what() + ")";
    status = -1;
  }
  if (status < 0) {
    if (reason.empty() && errno != 0) reason = std::string(" (") + std::strerror(errno) + ")";
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw Error("WriteCloud: cannot write " + QuotedPath(path) + reason);
  }
  ReplaceWithTemporary(temporary, path);  // flushed to disk, then renamed over the old file
}

}  // namespace uwscan::perception
