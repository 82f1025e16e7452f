#include "perception/cloud/pcd_reader.hpp"

#include <pcl/io/lzf.h>

#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <initializer_list>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"

namespace uwscan::perception {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kMaxHeaderBytes = 1 << 16;
// LZF turns 3 bytes into at most 264: a larger claimed size is damage, not data.
constexpr std::uint64_t kMaxInflation = 90;

struct Field {
  std::string name;
  int size = 0;                 // bytes per value
  char type = 0;                // 'I', 'U' or 'F'
  int count = 1;                // values per point
  std::size_t offset = 0;       // within a binary point
  std::size_t first_value = 0;  // among an ascii point's values
};

struct Header {
  std::vector<Field> fields;
  std::optional<Eigen::Isometry3d> viewpoint;
  std::string viewpoint_error;
  std::uint64_t points = 0;
  std::string data;  // ascii, binary, binary_compressed
  std::size_t body_offset = 0;
  std::size_t point_step = 0;
};

template <typename T>
bool ParseNumber(const std::string& word, T& value) {
  const auto parsed = std::from_chars(word.data(), word.data() + word.size(), value);
  return parsed.ec == std::errc() && parsed.ptr == word.data() + word.size();
}

std::vector<std::string> Words(std::istringstream& line) {
  std::vector<std::string> words;
  for (std::string word; line >> word;) words.push_back(word);
  return words;
}

// The header's values as its lines give them, before they are checked against each other.
struct HeaderLines {
  std::vector<std::string> fields;
  std::vector<int> sizes, counts;
  std::string types;
  std::optional<std::uint64_t> width, height, points;
  std::string data;
  std::optional<Eigen::Isometry3d> viewpoint;
  std::string viewpoint_error;
};

// A value of a SIZE or COUNT line: an integer in [1, max].
int FieldValue(const std::string& word, int max,
               const std::function<Error(const std::string&)>& bad) {
  int value = 0;
  if (!ParseNumber(word, value) || value < 1 || value > max) {
    throw bad("'" + word.substr(0, 20) + "' is not a valid value");
  }
  return value;
}

// A value of a TYPE line: I, U or F.
char FieldType(const std::string& word, const std::function<Error(const std::string&)>& bad) {
  if (word.size() != 1 || (word[0] != 'I' && word[0] != 'U' && word[0] != 'F')) {
    throw bad("'" + word.substr(0, 20) + "' is not I, U or F");
  }
  return word[0];
}

// A VIEWPOINT line's "tx ty tz qw qx qy qz": the sensor's pose in the file's frame.
Eigen::Isometry3d Viewpoint(const std::vector<std::string>& words,
                            const std::function<Error(const std::string&)>& bad) {
  double v[7];
  if (words.size() != 7) throw bad("expected 7 numbers: tx ty tz qw qx qy qz");
  for (std::size_t i = 0; i < 7; ++i) {
    const std::string word = words[i].starts_with('+') ? words[i].substr(1) : words[i];
    if (!ParseNumber(word, v[i]) || !std::isfinite(v[i])) {
      throw bad("'" + words[i].substr(0, 20) + "' is not a finite number");
    }
  }
  const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
  if (!(q.norm() > 1e-6)) throw bad("the orientation quaternion has zero length");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  return T;
}

// The values of one header line (`key` and the words after it, at `where`) added to `lines`.
void ReadHeaderLine(const std::string& key, const std::vector<std::string>& words,
                    const std::string& where, HeaderLines& lines) {
  const std::function<Error(const std::string&)> bad = [&](const std::string& what) {
    return Error(where + " (" + key + "): " + what);
  };
  if (key == "FIELDS") {
    lines.fields.insert(lines.fields.end(), words.begin(), words.end());
  } else if (key == "SIZE" || key == "COUNT") {
    std::vector<int>& values = key == "SIZE" ? lines.sizes : lines.counts;
    for (const std::string& word : words) {
      values.push_back(FieldValue(word, key == "SIZE" ? 8 : 100000, bad));
    }
  } else if (key == "TYPE") {
    for (const std::string& word : words) lines.types.push_back(FieldType(word, bad));
  } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
    std::uint64_t value = 0;
    if (words.size() != 1 || !ParseNumber(words[0], value)) throw bad("expected one count");
    (key == "WIDTH" ? lines.width : key == "HEIGHT" ? lines.height : lines.points) = value;
  } else if (key == "DATA") {
    if (words.size() != 1 ||
        (words[0] != "ascii" && words[0] != "binary" && words[0] != "binary_compressed")) {
      throw bad("expected ascii, binary or binary_compressed");
    }
    lines.data = words[0];
  } else if (key == "VIEWPOINT") {
    // Kept aside: only a reader that needs the sensor's pose refuses a bad one.
    try {
      lines.viewpoint = Viewpoint(words, bad);
    } catch (const Error& e) {
      lines.viewpoint_error = e.what();
    }
  } else if (!key.empty() && (std::isdigit(static_cast<unsigned char>(key[0])) || key[0] == '-' ||
                              key[0] == '+' || key[0] == '.')) {
    throw Error(where +
                ": a number where a header key belongs: the points start with no DATA "
                "line before them");
  } else {
    throw Error(where + ": unknown key '" + key.substr(0, 40) + "': not a PCD header");
  }
}

// The fields with their sizes, types and counts (1 when there is no COUNT line), laid out one
// after another in a point.
std::vector<Field> LayOutFields(const HeaderLines& lines, const std::string& name) {
  if (lines.fields.empty()) throw Error(name + ": the header has no FIELDS");
  const std::size_t n = lines.fields.size();
  const std::vector<int> counts = lines.counts.empty() ? std::vector<int>(n, 1) : lines.counts;
  if (lines.sizes.size() != n || lines.types.size() != n || counts.size() != n) {
    throw Error(name + ": FIELDS, SIZE, TYPE and COUNT list different numbers of fields");
  }
  std::vector<Field> fields;
  std::size_t offset = 0;
  for (std::size_t f = 0; f < n; ++f) {
    Field field{lines.fields[f], lines.sizes[f], lines.types[f], counts[f]};
    const bool valid = field.type == 'F' ? (field.size == 4 || field.size == 8)
                                         : (field.size == 1 || field.size == 2 || field.size == 4 ||
                                            field.size == 8);
    if (!valid) {
      throw Error(name + ": field '" + field.name + "' has type " + field.type + " of size " +
                  std::to_string(field.size));
    }
    field.offset = offset;
    offset += std::size_t(field.size) * std::size_t(field.count);
    field.first_value = f == 0 ? 0 : fields[f - 1].first_value + std::size_t(fields[f - 1].count);
    fields.push_back(field);
  }
  return fields;
}

// The number of points: POINTS, which must be WIDTH x HEIGHT when both are given; without it,
// WIDTH x HEIGHT (HEIGHT 1 when not given).
std::uint64_t PointCount(const HeaderLines& lines, const std::string& name) {
  const std::optional<std::uint64_t>& width = lines.width;
  const std::optional<std::uint64_t>& height = lines.height;
  constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
  if (!lines.points) {
    if (!width) throw Error(name + ": the header has neither POINTS nor WIDTH");
    if (height && *height != 0 && *width > kMax / *height) {
      throw Error(name + ": WIDTH x HEIGHT overflows");
    }
    return *width * (height ? *height : 1);
  }
  if (width && height && *height != 0 && *width <= kMax / *height &&
      *width * *height != *lines.points) {
    throw Error(name + ": POINTS " + std::to_string(*lines.points) + " is not WIDTH x HEIGHT");
  }
  return *lines.points;
}

Header ParseHeader(const std::string& file, const std::string& name) {
  HeaderLines lines;
  std::size_t at = 0;
  for (int number = 1; lines.data.empty(); ++number) {
    if (at >= file.size() || at > kMaxHeaderBytes)
      throw Error(name + ": no DATA line: not a PCD file");
    std::size_t end = file.find('\n', at);
    if (end == std::string::npos) end = file.size();
    std::istringstream stream(file.substr(at, end - at));
    at = end + 1;
    std::string key;
    stream >> key;
    if (key.empty() || key[0] == '#' || key == "VERSION") continue;
    ReadHeaderLine(key, Words(stream), name + ": header line " + std::to_string(number), lines);
  }
  Header header;
  header.data = lines.data;
  header.viewpoint = lines.viewpoint;
  header.viewpoint_error = lines.viewpoint_error;
  header.body_offset = std::min(at, file.size());
  header.fields = LayOutFields(lines, name);
  for (const Field& field : header.fields) {
    header.point_step += std::size_t(field.size) * std::size_t(field.count);
  }
  header.points = PointCount(lines, name);
  return header;
}

const Field* FindField(const Header& header, std::initializer_list<const char*> names) {
  for (const Field& field : header.fields) {
    for (const char* n : names) {
      if (field.name == n) return &field;
    }
  }
  return nullptr;
}

double Decode(const Field& field, const char* bytes) {
  auto as = [bytes]<typename T>(T) {
    T v;
    std::memcpy(&v, bytes, sizeof(T));
    return static_cast<double>(v);
  };
  switch (field.type) {
    case 'I':
      return field.size == 1   ? as(std::int8_t{})
             : field.size == 2 ? as(std::int16_t{})
             : field.size == 4 ? as(std::int32_t{})
                               : as(std::int64_t{});
    case 'U':
      return field.size == 1   ? as(std::uint8_t{})
             : field.size == 2 ? as(std::uint16_t{})
             : field.size == 4 ? as(std::uint32_t{})
                               : as(std::uint64_t{});
    default:
      return field.size == 4 ? as(float{}) : as(double{});
  }
}

// Every point's values, field by field, from any of the three encodings.
class PointValues {
 public:
  // Binary points, `stride` bytes apart, each field at its offset; or structure of arrays.
  PointValues(std::string_view bytes, const Header& header, bool structure_of_arrays)
      : bytes_(bytes), header_(header), soa_(structure_of_arrays) {}
  double Value(const Field& field, std::uint64_t point) const {
    if (soa_) {
      // binary_compressed: each field's values for all points together, in field order.
      return Decode(field, bytes_.data() + field.offset * header_.points +
                               point * std::size_t(field.size) * std::size_t(field.count));
    }
    return Decode(field, bytes_.data() + point * header_.point_step + field.offset);
  }

 private:
  std::string_view bytes_;
  const Header& header_;
  bool soa_;
};

// `value(field, point)` gives a field's first value at a point.
template <typename Value>
void Extract(const Header& header, const std::string& name, PcdContent& content,
             const Value& value) {
  const Field* xyz[3] = {FindField(header, {"x"}), FindField(header, {"y"}),
                         FindField(header, {"z"})};
  const Field* n[3] = {FindField(header, {"normal_x", "nx"}), FindField(header, {"normal_y", "ny"}),
                       FindField(header, {"normal_z", "nz"})};
  if (!xyz[0] || !xyz[1] || !xyz[2]) throw Error(name + " has no x, y and z fields");
  const Field* intensity = FindField(header, {"intensity"});
  const bool normals = n[0] && n[1] && n[2];
  content.points.reserve(header.points);
  if (normals) content.normals.reserve(header.points);
  if (intensity) content.intensity.reserve(header.points);
  for (std::uint64_t i = 0; i < header.points; ++i) {
    content.points.emplace_back(value(*xyz[0], i), value(*xyz[1], i), value(*xyz[2], i));
    if (normals) content.normals.emplace_back(value(*n[0], i), value(*n[1], i), value(*n[2], i));
    if (intensity) content.intensity.push_back(value(*intensity, i));
  }
}

void ReadAscii(const std::string& file, const Header& header, const std::string& name,
               PcdContent& content) {
  std::size_t values_per_point = 0;
  for (const Field& field : header.fields) values_per_point += std::size_t(field.count);
  const std::size_t left = file.size() - header.body_offset;
  if (header.points > left / (2 * values_per_point) + 1) {
    throw Error(name + ": " + std::to_string(header.points) + " points cannot fit in the " +
                std::to_string(left) + " bytes of ascii data");
  }
  std::vector<double> values;
  values.reserve(header.points * values_per_point);
  const char* p = file.data() + header.body_offset;
  const char* end = file.data() + file.size();
  for (std::uint64_t k = 0; k < header.points * values_per_point; ++k) {
    while (p < end && std::isspace(static_cast<unsigned char>(*p))) ++p;
    double value = 0.0;
    const std::from_chars_result parsed = std::from_chars(p, end, value);
    if (parsed.ec == std::errc::result_out_of_range) {
      value = std::numeric_limits<double>::infinity();
    } else if (parsed.ec != std::errc() || parsed.ptr == p) {
      throw Error(name + ": point " + std::to_string(k / values_per_point) + ": expected a number");
    }
    values.push_back(value);
    p = parsed.ptr;
  }
  Extract(header, name, content, [&](const Field& field, std::uint64_t i) {
    return values[i * values_per_point + field.first_value];
  });
}

}  // namespace

PcdContent ReadPcd(const fs::path& path) {
  const std::string name = QuotedPath(path) + " (read as PCD)";
  const std::string file = ReadFileBytes(path);
  const Header header = ParseHeader(file, name);
  PcdContent content;
  content.T_file_sensor = header.viewpoint;
  content.viewpoint_error = header.viewpoint_error;
  if (header.data == "ascii") {
    ReadAscii(file, header, name, content);
    return content;
  }
  const std::string_view body(file.data() + header.body_offset, file.size() - header.body_offset);
  if (header.data == "binary") {
    if (header.point_step == 0 || header.points > body.size() / header.point_step) {
      throw Error(name + ": " + std::to_string(header.points) + " points of " +
                  std::to_string(header.point_step) + " bytes do not fit in the " +
                  std::to_string(body.size()) + " bytes of binary data");
    }
    const PointValues values(body, header, false);
    Extract(header, name, content,
            [&](const Field& f, std::uint64_t i) { return values.Value(f, i); });
    return content;
  }
  // binary_compressed: uint32 compressed size, uint32 inflated size, then LZF data.
  std::uint32_t sizes[2];
  if (body.size() < sizeof(sizes)) throw Error(name + ": binary_compressed data is cut short");
  std::memcpy(sizes, body.data(), sizeof(sizes));
  if constexpr (std::endian::native != std::endian::little) {
    sizes[0] = __builtin_bswap32(sizes[0]);
    sizes[1] = __builtin_bswap32(sizes[1]);
  }
  const std::uint64_t expected = header.points * header.point_step;
  if (header.points != 0 && expected / header.points != header.point_step)
    throw Error(name + ": the point count overflows");
  if (sizes[0] > body.size() - sizeof(sizes) || sizes[1] != expected ||
      sizes[1] > kMaxInflation * std::uint64_t(sizes[0]) + 1024) {
    throw Error(name + ": binary_compressed sizes (" + std::to_string(sizes[0]) + " -> " +
                std::to_string(sizes[1]) + " bytes) do not match the header or the file");
  }
  std::string inflated(sizes[1], '\0');
  if (sizes[1] > 0 && pcl::lzfDecompress(body.data() + sizeof(sizes), sizes[0], inflated.data(),
                                         sizes[1]) != sizes[1]) {
    throw Error(name + ": binary_compressed data does not inflate to its size (damaged)");
  }
  const PointValues values(inflated, header, true);
  Extract(header, name, content,
          [&](const Field& f, std::uint64_t i) { return values.Value(f, i); });
  return content;
}

}  // namespace uwscan::perception
