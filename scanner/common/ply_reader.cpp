#include "scanner/common/ply_reader.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <initializer_list>
#include <limits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"

namespace uwscan::scanner {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kMaxHeaderBytes = 1 << 16;

enum class Encoding { kAscii, kLittleEndian, kBigEndian };

struct ScalarType {
  char kind = 0;  // 'i' signed, 'u' unsigned, 'f' floating point
  int bytes = 0;
};

std::optional<ScalarType> TypeNamed(std::string_view name) {
  if (name == "char" || name == "int8") return ScalarType{'i', 1};
  if (name == "uchar" || name == "uint8") return ScalarType{'u', 1};
  if (name == "short" || name == "int16") return ScalarType{'i', 2};
  if (name == "ushort" || name == "uint16") return ScalarType{'u', 2};
  if (name == "int" || name == "int32") return ScalarType{'i', 4};
  if (name == "uint" || name == "uint32") return ScalarType{'u', 4};
  if (name == "float" || name == "float32") return ScalarType{'f', 4};
  if (name == "double" || name == "float64") return ScalarType{'f', 8};
  return std::nullopt;
}

struct Property {
  std::string name;
  ScalarType type;
  std::optional<ScalarType> list_count;  // a list property: the type of its length
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

// Reads values one after another from the body, ascii or binary, never past its end.
class BodyCursor {
 public:
  BodyCursor(std::string_view body, Encoding encoding) : body_(body), encoding_(encoding) {}

  // False when the body ends first or the text is not a number.
  bool Read(ScalarType type, double& value) {
    if (encoding_ == Encoding::kAscii) return ReadText(value);
    if (body_.size() - at_ < std::size_t(type.bytes)) return false;
    std::uint8_t bytes[8];
    std::memcpy(bytes, body_.data() + at_, std::size_t(type.bytes));
    at_ += std::size_t(type.bytes);
    const bool swap = (encoding_ == Encoding::kBigEndian) == (std::endian::native == std::endian::little);
    if (swap) std::reverse(bytes, bytes + type.bytes);
    value = Decode(type, bytes);
    return true;
  }

  // The fewest bytes one more value can take: a list longer than the rest of the body is damage.
  std::size_t BytesLeft() const { return body_.size() - at_; }

 private:
  static double Decode(ScalarType type, const std::uint8_t* bytes) {
    auto as = [bytes]<typename T>(T) {
      T v;
      std::memcpy(&v, bytes, sizeof(T));
      return static_cast<double>(v);
    };
    switch (type.kind) {
      case 'i':
        return type.bytes == 1 ? as(std::int8_t{}) : type.bytes == 2 ? as(std::int16_t{}) : as(std::int32_t{});
      case 'u':
        return type.bytes == 1 ? as(std::uint8_t{}) : type.bytes == 2 ? as(std::uint16_t{}) : as(std::uint32_t{});
      default:
        return type.bytes == 4 ? as(float{}) : as(double{});
    }
  }

  bool ReadText(double& value) {
    while (at_ < body_.size() && std::isspace(static_cast<unsigned char>(body_[at_]))) ++at_;
    const char* begin = body_.data() + at_;
    const char* end = body_.data() + body_.size();
    if (begin < end && *begin == '+') ++begin;
    const std::from_chars_result parsed = std::from_chars(begin, end, value);
    if (parsed.ec == std::errc::result_out_of_range) {
      value = std::numeric_limits<double>::infinity();  // kept as read; the caller judges
    } else if (parsed.ec != std::errc() || parsed.ptr == begin) {
      return false;
    }
    at_ = static_cast<std::size_t>(parsed.ptr - body_.data());
    return true;
  }

  std::string_view body_;
  Encoding encoding_;
  std::size_t at_ = 0;
};

struct Header {
  Encoding encoding = Encoding::kAscii;
  std::vector<Element> elements;
  std::size_t body_offset = 0;
};

Header ParseHeader(const std::string& file, const std::string& name) {
  if (file.rfind("ply", 0) != 0 || file.size() < 4 || (file[3] != '\n' && file[3] != '\r')) {
    throw Error(name + ": not a PLY file (it does not start with 'ply')");
  }
  const std::size_t end = file.find("end_header", 0);
  if (end == std::string::npos || end > kMaxHeaderBytes) {
    throw Error(name + ": no 'end_header' in the first " + std::to_string(kMaxHeaderBytes) + " bytes");
  }
  Header header;
  header.body_offset = file.find('\n', end);
  if (header.body_offset == std::string::npos) throw Error(name + ": the header does not end with a new line");
  ++header.body_offset;
  std::istringstream lines(file.substr(0, end));
  std::string line;
  bool format_seen = false;
  for (int number = 1; std::getline(lines, line); ++number) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    const std::string where = name + ": header line " + std::to_string(number);
    if (keyword.empty() || keyword == "ply" || keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "format") {
      std::string encoding, version;
      words >> encoding >> version;
      if (encoding == "ascii") header.encoding = Encoding::kAscii;
      else if (encoding == "binary_little_endian") header.encoding = Encoding::kLittleEndian;
      else if (encoding == "binary_big_endian") header.encoding = Encoding::kBigEndian;
      else throw Error(where + ": unknown format '" + encoding + "'");
      if (version != "1.0") throw Error(where + ": PLY version '" + version + "', expected 1.0");
      format_seen = true;
    } else if (keyword == "element") {
      Element element;
      std::string count;
      words >> element.name >> count;
      const auto parsed = std::from_chars(count.data(), count.data() + count.size(), element.count);
      if (element.name.empty() || parsed.ec != std::errc() || parsed.ptr != count.data() + count.size()) {
        throw Error(where + ": expected 'element NAME COUNT', got '" + line.substr(0, 80) + "'");
      }
      header.elements.push_back(element);
    } else if (keyword == "property") {
      if (header.elements.empty()) throw Error(where + ": a property before any element");
      Property property;
      std::string type;
      words >> type;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type >> property.name;
        property.list_count = TypeNamed(count_type);
        const std::optional<ScalarType> item = TypeNamed(item_type);
        if (!property.list_count || property.list_count->kind == 'f' || !item || property.name.empty()) {
          throw Error(where + ": expected 'property list COUNT_TYPE ITEM_TYPE NAME', got '" + line.substr(0, 80) + "'");
        }
        property.type = *item;
      } else {
        words >> property.name;
        const std::optional<ScalarType> scalar = TypeNamed(type);
        if (!scalar || property.name.empty()) {
          throw Error(where + ": expected 'property TYPE NAME', got '" + line.substr(0, 80) + "'");
        }
        property.type = *scalar;
      }
      header.elements.back().properties.push_back(property);
    } else {
      throw Error(where + ": unknown keyword '" + keyword.substr(0, 40) + "'");
    }
  }
  if (!format_seen) throw Error(name + ": the header has no 'format' line");
  return header;
}

int IndexOf(const Element& element, std::initializer_list<const char*> names) {
  for (std::size_t p = 0; p < element.properties.size(); ++p) {
    for (const char* n : names) {
      if (element.properties[p].name == n && !element.properties[p].list_count) return int(p);
    }
  }
  return -1;
}

// The fewest bytes a row of `element` takes in the body: what bounds its count before reading.
std::size_t MinRowBytes(const Element& element, Encoding encoding) {
  std::size_t bytes = 0;
  for (const Property& p : element.properties) {
    if (encoding == Encoding::kAscii) bytes += 2;  // a digit and a separator
    else bytes += std::size_t(p.list_count ? p.list_count->bytes : p.type.bytes);
  }
  return bytes;
}

}  // namespace

PlyContent ReadPly(const fs::path& path, bool faces) {
  const std::string name = QuotedPath(path);
  const std::string file = ReadFileBytes(path);
  const Header header = ParseHeader(file, name);

  const std::string_view body(file.data() + header.body_offset, file.size() - header.body_offset);
  BodyCursor cursor(body, header.encoding);
  PlyContent content;
  bool vertices_seen = false;
  std::vector<std::vector<int>> polygons;
  for (const Element& element : header.elements) {
    const std::size_t min_row = MinRowBytes(element, header.encoding);
    if (min_row > 0 && element.count > cursor.BytesLeft() / min_row) {
      throw Error(name + ": element " + element.name + " claims " + std::to_string(element.count) +
                  " rows, more than the " + std::to_string(cursor.BytesLeft()) + " bytes left can hold");
    }
    const bool is_vertex = element.name == "vertex";
    const bool is_face = faces && element.name == "face";
    const int xyz[3] = {IndexOf(element, {"x"}), IndexOf(element, {"y"}), IndexOf(element, {"z"})};
    const int n[3] = {IndexOf(element, {"nx", "normal_x"}), IndexOf(element, {"ny", "normal_y"}),
                      IndexOf(element, {"nz", "normal_z"})};
    const bool with_normals = n[0] >= 0 && n[1] >= 0 && n[2] >= 0;
    const int intensity = IndexOf(element, {"intensity", "scalar_intensity", "scalar_Intensity"});
    if (is_vertex) {
      if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0) throw Error(name + ": element vertex has no x, y and z");
      vertices_seen = true;
      content.vertices.reserve(element.count);
      if (with_normals) content.normals.reserve(element.count);
      if (intensity >= 0) content.intensity.reserve(element.count);
    }
    std::vector<double> row(element.properties.size());
    for (std::uint64_t r = 0; r < element.count; ++r) {
      auto short_of = [&](const std::string& what) {
        return Error(name + ": element " + element.name + " row " + std::to_string(r) + ": " + what);
      };
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const Property& property = element.properties[p];
        if (!property.list_count) {
          if (!cursor.Read(property.type, row[p])) throw short_of("the file ends or a value is not a number");
          continue;
        }
        double length = 0.0;
        if (!cursor.Read(*property.list_count, length) || length < 0.0 || length != std::floor(length) ||
            length > double(cursor.BytesLeft())) {
          throw short_of("list '" + property.name + "' has no valid length");
        }
        const bool keep = is_face && (property.name == "vertex_indices" || property.name == "vertex_index");
        std::vector<int> polygon;
        for (std::size_t k = 0; k < std::size_t(length); ++k) {
          double item = 0.0;
          if (!cursor.Read(property.type, item)) throw short_of("list '" + property.name + "' is cut short");
          if (keep) {
            if (!(item >= 0.0 && item < 2147483647.0) || item != std::floor(item)) {
              throw short_of("vertex index " + std::to_string(item) + " is not a valid index");
            }
            polygon.push_back(int(item));
          }
        }
        if (keep) polygons.push_back(std::move(polygon));
      }
      if (is_vertex) {
        content.vertices.emplace_back(row[std::size_t(xyz[0])], row[std::size_t(xyz[1])], row[std::size_t(xyz[2])]);
        if (with_normals) {
          content.normals.emplace_back(row[std::size_t(n[0])], row[std::size_t(n[1])], row[std::size_t(n[2])]);
        }
        if (intensity >= 0) content.intensity.push_back(row[std::size_t(intensity)]);
      }
    }
  }
  if (!vertices_seen) throw Error(name + ": no vertex element");
  for (std::size_t f = 0; f < polygons.size(); ++f) {
    const std::vector<int>& polygon = polygons[f];
    if (polygon.size() < 3) {
      throw Error(name + ": face " + std::to_string(f) + " has " + std::to_string(polygon.size()) +
                  " vertices, expected at least 3");
    }
    for (int index : polygon) {
      if (std::size_t(index) >= content.vertices.size()) {
        throw Error(name + ": face " + std::to_string(f) + " names vertex " + std::to_string(index) +
                    " of " + std::to_string(content.vertices.size()));
      }
    }
    for (std::size_t k = 1; k + 1 < polygon.size(); ++k) content.triangles.emplace_back(polygon[0], polygon[k], polygon[k + 1]);
  }
  return content;
}

}  // namespace uwscan::scanner
