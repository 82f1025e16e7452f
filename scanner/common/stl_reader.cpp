#include "scanner/common/stl_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"
#include "scanner/common/fnv1a.hpp"

namespace uwscan::scanner {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kBinaryHeaderBytes = 84;  // 80-byte header and the uint32 count
constexpr std::size_t kBinaryTriangleBytes = 50;

// Gives each distinct vertex (by its float32 bits, as STL stores it) one index.
class VertexMerger {
 public:
  explicit VertexMerger(TriangleMesh& mesh) : mesh_(mesh) {}

  int Index(float x, float y, float z) {
    Key key;
    std::memcpy(&key.bits[0], &x, 4);
    std::memcpy(&key.bits[1], &y, 4);
    std::memcpy(&key.bits[2], &z, 4);
    const auto [it, added] = index_.try_emplace(key, static_cast<int>(mesh_.vertices.size()));
    if (added) mesh_.vertices.emplace_back(x, y, z);
    return it->second;
  }

  // A triangle, unless two of its corners are the same vertex.
  void AddTriangle(int a, int b, int c) {
    if (a != b && b != c && a != c) mesh_.triangles.emplace_back(a, b, c);
  }

 private:
  struct Key {
    std::uint32_t bits[3];
    bool operator==(const Key& o) const { return std::memcmp(bits, o.bits, sizeof(bits)) == 0; }
  };
  struct Hash {
    std::size_t operator()(const Key& k) const {
      return static_cast<std::size_t>(
          Fnv1a64(reinterpret_cast<const char*>(k.bits), sizeof(k.bits)));
    }
  };
  TriangleMesh& mesh_;
  std::unordered_map<Key, int, Hash> index_;
};

float LittleEndianFloat(const char* bytes) {
  std::uint32_t bits = 0;
  for (int i = 3; i >= 0; --i) bits = (bits << 8) | static_cast<unsigned char>(bytes[i]);
  float value = 0.0f;
  std::memcpy(&value, &bits, 4);
  return value;
}

std::uint32_t BinaryCount(const std::string& bytes) {
  std::uint32_t count = 0;
  for (int i = 3; i >= 0; --i)
    count = (count << 8) | static_cast<unsigned char>(bytes[80 + std::size_t(i)]);
  return count;
}

// Whether the first bytes are text, as an ASCII STL is: binary floats hold NULs and control
// bytes, even behind a header that starts with "solid". NULs and DOS end-of-file marks (0x1a)
// padding the end of a text file do not count.
bool LooksLikeText(const std::string& bytes) {
  const std::size_t padded = bytes.find_last_not_of(std::string("\0\x1a", 2));
  const std::size_t text = padded == std::string::npos ? 0 : padded + 1;
  const std::size_t n = std::min<std::size_t>(text, 4096);
  return std::all_of(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(n), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return u >= 0x20 || c == '\n' || c == '\r' || c == '\t' || c == '\f' || c == '\v';
  });
}

// What is wrong with a binary STL's size: the count its header claims against the bytes there.
std::string BinarySizeMismatch(const std::string& bytes) {
  if (bytes.size() < kBinaryHeaderBytes) {
    return "only " + std::to_string(bytes.size()) + " bytes, fewer than the 84 of a header";
  }
  const std::uint32_t count = BinaryCount(bytes);
  return "its header claims " + std::to_string(count) + " triangles (84 + 50 x " +
         std::to_string(count) + " = " +
         std::to_string(kBinaryHeaderBytes + kBinaryTriangleBytes * std::size_t{count}) +
         " bytes) and the file has " + std::to_string(bytes.size());
}

bool IsBinary(const std::string& bytes) {
  return bytes.size() >= kBinaryHeaderBytes &&
         bytes.size() ==
             kBinaryHeaderBytes + kBinaryTriangleBytes * std::size_t{BinaryCount(bytes)};
}

TriangleMesh ReadBinary(const std::string& bytes) {
  const std::uint32_t count = BinaryCount(bytes);
  TriangleMesh mesh;
  VertexMerger merger(mesh);
  for (std::size_t t = 0; t < count; ++t) {
    const char* corner =
        bytes.data() + kBinaryHeaderBytes + t * kBinaryTriangleBytes + 12;  // past the normal
    int index[3];
    for (int k = 0; k < 3; ++k, corner += 12) {
      index[k] = merger.Index(LittleEndianFloat(corner), LittleEndianFloat(corner + 4),
                              LittleEndianFloat(corner + 8));
    }
    merger.AddTriangle(index[0], index[1], index[2]);
  }
  return mesh;
}

// Whitespace-separated words with the line each is on.
class Words {
 public:
  explicit Words(std::string_view text) : text_(text) {}

  // False at the end of the text.
  bool Next(std::string_view& word) {
    while (at_ < text_.size() && IsSpace(text_[at_])) {
      if (text_[at_] == '\n') ++line_;
      ++at_;
    }
    if (at_ >= text_.size()) return false;
    const std::size_t begin = at_;
    while (at_ < text_.size() && !IsSpace(text_[at_])) ++at_;
    word = text_.substr(begin, at_ - begin);
    return true;
  }
  int line() const { return line_; }
  // Skips to the start of the next line (past the solid's name, which may be any words).
  void SkipLine() {
    while (at_ < text_.size() && text_[at_] != '\n') ++at_;
  }

 private:
  static bool IsSpace(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
  }
  std::string_view text_;
  std::size_t at_ = 0;
  int line_ = 1;
};

TriangleMesh ReadAscii(const std::string& text, const std::string& name) {
  Words words(text);
  auto at = [&](const std::string& what) {
    return Error(name + " line " + std::to_string(words.line()) + ": " + what);
  };
  std::string_view word;
  if (!words.Next(word) || word != "solid")
    throw Error(name + ": neither binary STL (84 + 50 n bytes) nor ASCII STL");
  words.SkipLine();
  TriangleMesh mesh;
  VertexMerger merger(mesh);
  std::vector<int> loop;
  bool in_loop = false, ended = false;
  while (words.Next(word)) {
    if (word == "vertex") {
      if (!in_loop) throw at("a vertex outside 'outer loop'");
      float xyz[3];
      for (float& value : xyz) {
        std::string_view number;
        if (!words.Next(number)) throw at("the file ends inside a vertex");
        const char* begin =
            number.data() + (number.front() == '+' ? 1 : 0);  // from_chars takes no '+'
        const std::from_chars_result parsed =
            std::from_chars(begin, number.data() + number.size(), value);
        if (parsed.ec != std::errc() || parsed.ptr != number.data() + number.size()) {
          throw at("expected a vertex 'x y z', got '" + std::string(number.substr(0, 40)) + "'");
        }
      }
      loop.push_back(merger.Index(xyz[0], xyz[1], xyz[2]));
    } else if (word == "loop") {
      if (in_loop) throw at("'outer loop' inside a loop");
      in_loop = true;
      loop.clear();
    } else if (word == "endloop") {
      if (!in_loop || loop.size() < 3) throw at("a loop of fewer than 3 vertices");
      for (std::size_t k = 1; k + 1 < loop.size(); ++k)
        merger.AddTriangle(loop[0], loop[k], loop[k + 1]);
      in_loop = false;
    } else if (word == "endsolid") {
      if (in_loop) throw at("'endsolid' inside a loop");
      ended = true;
      words.SkipLine();  // past the solid's name
    } else if (word == "solid") {
      if (!ended) throw at("'solid' inside a solid");
      ended = false;  // files with several solids: one mesh of them all
      words.SkipLine();
    }
    // "facet normal nx ny nz", "outer" and "endfacet" carry nothing needed.
  }
  if (in_loop || !ended) throw Error(name + ": cut short (no 'endsolid')");
  return mesh;
}

}  // namespace

TriangleMesh ReadStl(const fs::path& path) {
  const std::string name = QuotedPath(path) + " (read as STL)";
  const std::string bytes = ReadFileBytes(path);
  if (IsBinary(bytes)) return ReadBinary(bytes);
  if (LooksLikeText(bytes)) return ReadAscii(bytes, name);
  throw Error(name + ": binary (not text), but " + BinarySizeMismatch(bytes));
}

}  // namespace uwscan::scanner
