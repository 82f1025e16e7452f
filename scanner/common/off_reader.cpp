#include "scanner/common/off_reader.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"

namespace uwscan::scanner {
namespace {

namespace fs = std::filesystem;

// The file's lines without comments and blank lines, each with its line number.
class Lines {
 public:
  explicit Lines(std::string_view text) : text_(text) {}

  // False at the end of the file.
  bool Next(std::string_view& line, int& number) {
    while (at_ < text_.size()) {
      std::size_t end = text_.find('\n', at_);
      if (end == std::string_view::npos) end = text_.size();
      line = text_.substr(at_, end - at_);
      at_ = end + 1;
      number = ++number_;
      const std::size_t comment = line.find('#');
      if (comment != std::string_view::npos) line = line.substr(0, comment);
      if (line.find_first_not_of(" \t\r") != std::string_view::npos) return true;
    }
    return false;
  }

  std::size_t BytesLeft() const { return at_ < text_.size() ? text_.size() - at_ : 0; }

 private:
  std::string_view text_;
  std::size_t at_ = 0;
  int number_ = 0;
};

// The numbers at the start of a line, up to `count` of them.
std::vector<double> Numbers(std::string_view line, std::size_t count) {
  std::vector<double> numbers;
  const char* p = line.data();
  const char* end = line.data() + line.size();
  while (numbers.size() < count) {
    while (p < end && (*p == ' ' || *p == '\t' || *p == '\r')) ++p;
    if (p < end && *p == '+') ++p;
    double value = 0.0;
    const std::from_chars_result parsed = std::from_chars(p, end, value);
    if (parsed.ec != std::errc() || parsed.ptr == p) break;
    numbers.push_back(value);
    p = parsed.ptr;
  }
  return numbers;
}

}  // namespace

TriangleMesh ReadOff(const fs::path& path) {
  const std::string name = QuotedPath(path) + " (read as OFF)";
  const std::string text = ReadFileBytes(path);
  Lines lines(text);
  std::string_view line;
  int number = 0;
  auto at = [&](const std::string& what) {
    return Error(name + " line " + std::to_string(number) + ": " + what);
  };

  if (!lines.Next(line, number)) throw Error(name + ": empty, not an OFF mesh");
  const std::size_t keyword_end = line.find_first_of(" \t\r");
  const std::string_view keyword = line.substr(0, keyword_end);
  if (keyword != "OFF" && keyword != "COFF" && keyword != "NOFF" && keyword != "CNOFF") {
    throw at("expected OFF, not an OFF mesh");
  }
  // The counts may follow the keyword on its line or have a line of their own.
  std::vector<double> counts = keyword_end == std::string_view::npos
                                   ? std::vector<double>{}
                                   : Numbers(line.substr(keyword_end), 3);
  if (counts.empty()) {
    if (!lines.Next(line, number)) throw at("no vertex and face counts");
    counts = Numbers(line, 3);
  }
  if (counts.size() < 2 || counts[0] < 0 || counts[1] < 0 || counts[0] != std::floor(counts[0]) ||
      counts[1] != std::floor(counts[1])) {
    throw at("expected the counts 'vertices faces edges'");
  }
  // Every vertex and face takes at least two bytes (a digit and a new line).
  const double room = double(lines.BytesLeft()) / 2.0;
  if (counts[0] > room || counts[1] > room) throw at("the counts are more than the file can hold");
  const auto vertices = static_cast<std::size_t>(counts[0]);
  const auto faces = static_cast<std::size_t>(counts[1]);

  TriangleMesh mesh;
  mesh.vertices.reserve(vertices);
  for (std::size_t v = 0; v < vertices; ++v) {
    if (!lines.Next(line, number))
      throw Error(name + ": cut short after " + std::to_string(v) + " vertices");
    const std::vector<double> xyz = Numbers(line, 3);
    if (xyz.size() != 3) throw at("expected a vertex 'x y z'");
    mesh.vertices.emplace_back(xyz[0], xyz[1], xyz[2]);
  }
  for (std::size_t f = 0; f < faces; ++f) {
    if (!lines.Next(line, number))
      throw Error(name + ": cut short after " + std::to_string(f) + " faces");
    const std::vector<double> size = Numbers(line, 1);
    if (size.size() != 1 || size[0] < 3 || size[0] > double(line.size()) ||
        size[0] != std::floor(size[0])) {
      throw at("expected a face 'n i1 .. in' with n >= 3");
    }
    const std::vector<double> face = Numbers(line, 1 + static_cast<std::size_t>(size[0]));
    if (face.size() != 1 + static_cast<std::size_t>(size[0])) throw at("the face is cut short");
    for (std::size_t k = 1; k < face.size(); ++k) {
      if (!(face[k] >= 0.0 && face[k] < double(vertices)) || face[k] != std::floor(face[k])) {
        throw at("vertex index " + std::to_string(face[k]) + " is not one of the " +
                 std::to_string(vertices));
      }
    }
    for (std::size_t k = 2; k + 1 < face.size(); ++k) {
      mesh.triangles.emplace_back(int(face[1]), int(face[k]), int(face[k + 1]));
    }
  }
  return mesh;
}

}  // namespace uwscan::scanner
