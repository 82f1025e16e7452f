#include "scanner/common/ply_reader.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

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
    const bool swap =
        (encoding_ == Encoding::kBigEndian) == (std::endian::native == std::endian::little);
    if (swap) std::reverse(bytes, bytes + type.bytes);
    value = Decode(type, bytes);
    return true;
  }

  // The fewest bytes one more value can take: a list longer than the rest of the body is damage.
  std::size_t BytesLeft() const { return body_.size() - at_; }

  // Why Read failed here: the body ends, or (ascii) the word there is not a number.
  std::string WhyNoValue() const {
    std::size_t begin = at_;
    while (begin < body_.size() && std::isspace(static_cast<unsigned char>(body_[begin]))) ++begin;
    if (encoding_ != Encoding::kAscii || begin == body_.size()) return "the file ends";
    std::size_t end = begin;
    while (end < body_.size() && end - begin < 40 &&
           !std::isspace(static_cast<unsigned char>(body_[end])))
      ++end;
    return "'" + std::string(body_.substr(begin, end - begin)) + "' is not a number";
  }

 private:
  static double Decode(ScalarType type, const std::uint8_t* bytes) {
    auto as = [bytes]<typename T>(T) {
      T v;
      std::memcpy(&v, bytes, sizeof(T));
      return static_cast<double>(v);
    };
    switch (type.kind) {
      case 'i':
        return type.bytes == 1   ? as(std::int8_t{})
               : type.bytes == 2 ? as(std::int16_t{})
                                 : as(std::int32_t{});
      case 'u':
        return type.bytes == 1   ? as(std::uint8_t{})
               : type.bytes == 2 ? as(std::uint16_t{})
                                 : as(std::uint32_t{});
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
  if (end > kMaxHeaderBytes) {  // npos too
    throw Error(name + ": no 'end_header' in the first " + std::to_string(kMaxHeaderBytes) +
                " bytes");
  }
  Header header;
  header.body_offset = file.find('\n', end);
  if (header.body_offset == std::string::npos)
    throw Error(name + ": the header does not end with a new line");
  ++header.body_offset;
  std::istringstream lines(file.substr(0, end));
  std::string line;
  bool format_seen = false;
  for (int number = 1; std::getline(lines, line); ++number) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    const std::string where = name + ": header line " + std::to_string(number);
    if (keyword.empty() || keyword == "ply" || keyword == "comment" || keyword == "obj_info")
      continue;
    if (keyword == "format") {
      std::string encoding, version;
      words >> encoding >> version;
      if (encoding == "ascii")
        header.encoding = Encoding::kAscii;
      else if (encoding == "binary_little_endian")
        header.encoding = Encoding::kLittleEndian;
      else if (encoding == "binary_big_endian")
        header.encoding = Encoding::kBigEndian;
      else
        throw Error(where + ": unknown format '" + encoding + "'");
      if (version != "1.0") throw Error(where + ": PLY version '" + version + "', expected 1.0");
      format_seen = true;
    } else if (keyword == "element") {
      Element element;
      std::string count;
      words >> element.name >> count;
      const auto parsed = std::from_chars(count.data(), count.data() + count.size(), element.count);
      if (element.name.empty() || parsed.ec != std::errc() ||
          parsed.ptr != count.data() + count.size()) {
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
        if (!property.list_count || property.list_count->kind == 'f' || !item ||
            property.name.empty()) {
          throw Error(where + ": expected 'property list COUNT_TYPE ITEM_TYPE NAME', got '" +
                      line.substr(0, 80) + "'");
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
    if (encoding == Encoding::kAscii)
      bytes += 2;  // a digit and a separator
    else
      bytes += std::size_t(p.list_count ? p.list_count->bytes : p.type.bytes);
  }
  return bytes;
}

// The columns of a vertex row's values (-1: no such property).
struct VertexColumns {
  int xyz[3];
  int n[3];
  int intensity;
  bool with_normals() const { return n[0] >= 0 && n[1] >= 0 && n[2] >= 0; }
};

VertexColumns VertexColumnsOf(const Element& element) {
  return {{IndexOf(element, {"x"}), IndexOf(element, {"y"}), IndexOf(element, {"z"})},
          {IndexOf(element, {"nx", "normal_x"}), IndexOf(element, {"ny", "normal_y"}),
           IndexOf(element, {"nz", "normal_z"})},
          IndexOf(element, {"intensity", "scalar_intensity", "scalar_Intensity"})};
}

// Reads a PLY body element by element, keeping the vertices and, when asked, the faces.
class BodyReader {
 public:
  BodyReader(std::string_view body, Encoding encoding, const std::string& name, bool faces,
             std::uint64_t vertex_count)
      : cursor_(body, encoding),
        encoding_(encoding),
        name_(name),
        faces_(faces),
        vertex_count_(vertex_count) {}

  // Reads every row of `element`: the vertex element's points (with their normals and
  // intensities when it has them), a face element's polygons (their indices checked against the
  // header's vertex count even when the faces are not kept: a face past the vertices is damage
  // either way); other elements are read past.
  void Read(const Element& element) {
    RequireRowsFit(element);
    const bool is_vertex = element.name == "vertex";
    const bool is_face = element.name == "face";
    const VertexColumns columns = VertexColumnsOf(element);
    if (is_vertex) StartVertices(element, columns);
    std::vector<double> row(element.properties.size());
    for (std::uint64_t r = 0; r < element.count; ++r) {
      ReadRow(element, r, is_face, row);
      if (is_vertex) AddVertex(row, columns);
    }
  }

  // What was read, the faces fan-triangulated; throws when there was no vertex element or a
  // face is not a polygon of the vertices.
  PlyContent Finish() {
    if (!vertices_seen_) throw Error(name_ + ": no vertex element");
    for (std::size_t f = 0; f < polygons_.size(); ++f) {
      const std::vector<int>& polygon = polygons_[f];
      RequirePolygon(f, polygon);
      for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
        content_.triangles.emplace_back(polygon[0], polygon[k], polygon[k + 1]);
      }
    }
    return std::move(content_);
  }

 private:
  // A row's problem, named by the element and row.
  Error RowError(const Element& element, std::uint64_t r, const std::string& what) const {
    return Error(name_ + ": element " + element.name + " row " + std::to_string(r) + ": " + what);
  }

  // Throws when `element` claims more rows than the rest of the body can hold.
  void RequireRowsFit(const Element& element) const {
    const std::size_t min_row = MinRowBytes(element, encoding_);
    if (min_row > 0 && element.count > cursor_.BytesLeft() / min_row) {
      throw Error(name_ + ": element " + element.name + " claims " + std::to_string(element.count) +
                  " rows, more than the " + std::to_string(cursor_.BytesLeft()) +
                  " bytes left can hold");
    }
  }

  void StartVertices(const Element& element, const VertexColumns& columns) {
    if (columns.xyz[0] < 0 || columns.xyz[1] < 0 || columns.xyz[2] < 0) {
      throw Error(name_ + ": element vertex has no x, y and z");
    }
    vertices_seen_ = true;
    content_.vertices.reserve(element.count);
    if (columns.with_normals()) content_.normals.reserve(element.count);
    if (columns.intensity >= 0) content_.intensity.reserve(element.count);
  }

  // Row r of `element`: its scalar values into `row` (by property), the vertex indices of a
  // face's polygon into polygons_.
  void ReadRow(const Element& element, std::uint64_t r, bool is_face, std::vector<double>& row) {
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const Property& property = element.properties[p];
      if (!property.list_count) {
        if (!cursor_.Read(property.type, row[p])) {
          throw RowError(element, r, property.name + ": " + cursor_.WhyNoValue());
        }
        continue;
      }
      const bool indices =
          is_face && (property.name == "vertex_indices" || property.name == "vertex_index");
      std::vector<int> polygon = ReadList(element, r, property, indices);
      if (indices && faces_) polygons_.push_back(std::move(polygon));
    }
  }

  // The items of a list property; as vertex indices, each checked against the header's vertex
  // count, when `indices`, else read past (none).
  std::vector<int> ReadList(const Element& element, std::uint64_t r, const Property& property,
                            bool indices) {
    double length = 0.0;
    if (!cursor_.Read(*property.list_count, length) || length < 0.0 ||
        length != std::floor(length) || length > double(cursor_.BytesLeft())) {
      throw RowError(element, r, "list '" + property.name + "' has no valid length");
    }
    std::vector<int> polygon;
    for (std::size_t k = 0; k < std::size_t(length); ++k) {
      double item = 0.0;
      if (!cursor_.Read(property.type, item)) {
        throw RowError(element, r, "list '" + property.name + "' is cut short");
      }
      if (!indices) continue;
      if (!(item >= 0.0 && item < 2147483647.0) || item != std::floor(item)) {
        throw RowError(element, r,
                       "vertex index " + std::to_string(item) + " is not a valid index");
      }
      if (item >= double(vertex_count_)) {
        throw RowError(element, r,
                       "names vertex " + std::to_string(std::int64_t(item)) + " of " +
                           std::to_string(vertex_count_));
      }
      polygon.push_back(int(item));
    }
    return polygon;
  }

  void AddVertex(const std::vector<double>& row, const VertexColumns& c) {
    content_.vertices.emplace_back(row[std::size_t(c.xyz[0])], row[std::size_t(c.xyz[1])],
                                   row[std::size_t(c.xyz[2])]);
    if (c.with_normals()) {
      content_.normals.emplace_back(row[std::size_t(c.n[0])], row[std::size_t(c.n[1])],
                                    row[std::size_t(c.n[2])]);
    }
    if (c.intensity >= 0) content_.intensity.push_back(row[std::size_t(c.intensity)]);
  }

  // Throws unless face f has at least 3 vertices, all of them read.
  void RequirePolygon(std::size_t f, const std::vector<int>& polygon) const {
    if (polygon.size() < 3) {
      throw Error(name_ + ": face " + std::to_string(f) + " has " + std::to_string(polygon.size()) +
                  " vertices, expected at least 3");
    }
    for (int index : polygon) {
      if (std::size_t(index) >= content_.vertices.size()) {
        throw Error(name_ + ": face " + std::to_string(f) + " names vertex " +
                    std::to_string(index) + " of " + std::to_string(content_.vertices.size()));
      }
    }
  }

  BodyCursor cursor_;
  Encoding encoding_;
  const std::string& name_;
  bool faces_;
  std::uint64_t vertex_count_;  // the header's
  PlyContent content_;
  bool vertices_seen_ = false;
  std::vector<std::vector<int>> polygons_;
};

}  // namespace

PlyContent ReadPly(const fs::path& path, bool faces) {
  const std::string name = QuotedPath(path) + " (read as PLY)";
  const std::string file = ReadFileBytes(path);
  const Header header = ParseHeader(file, name);
  const std::string_view body(file.data() + header.body_offset, file.size() - header.body_offset);
  std::uint64_t vertex_count = 0;
  for (const Element& element : header.elements)
    vertex_count += element.name == "vertex" ? element.count : 0;
  BodyReader reader(body, header.encoding, name, faces, vertex_count);
  for (const Element& element : header.elements) reader.Read(element);
  return reader.Finish();
}

std::optional<long long> PlyFaceCount(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  for (int lines = 0; lines < 200 && std::getline(in, line); ++lines) {
    if (line.rfind("end_header", 0) == 0) break;
    std::istringstream words(line);
    std::string element, name;
    long long count = 0;
    if (words >> element >> name >> count && element == "element" && name == "face") return count;
  }
  return std::nullopt;
}

}  // namespace uwscan::scanner
