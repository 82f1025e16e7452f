#include "scanner/calibration/opencv_storage_reader.hpp"

#include <libxml/parser.h>
#include <libxml/tree.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <string_view>
#include <system_error>

#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"

namespace uwscan::scanner::calibration {
namespace {

constexpr std::uintmax_t kMaxFileBytes = 1 << 20;
constexpr int kMaxMatrixSide = 16;

// Thrown by the parsers below with what is wrong; Read() prefixes the file.
struct Refusal {
  std::string what;
};

[[noreturn]] void Refuse(const std::string& what) { throw Refusal{what}; }

// The whole of `text` as a number, or nothing (no leading or trailing characters).
template <class Number>
std::optional<Number> ParseWhole(std::string_view text) {
  Number value{};
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

std::string_view Trimmed(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t\r\n");
  return text.substr(first, last - first + 1);
}

// The checks every matrix read passes, whichever syntax carried it. dt is OpenCV's element
// type: one channel of u, c, w, s, i, f or d (bytes to doubles; all read as double).
OpenCvMatrix MakeMatrix(const std::string& name, const OpenCvNode& node) {
  const std::string where = "node '" + name + "': ";
  if (!node.malformed.empty()) Refuse(where + node.malformed);
  const auto r = ParseWhole<int>(Trimmed(node.rows));
  const auto c = ParseWhole<int>(Trimmed(node.cols));
  if (!r || !c || *r < 1 || *c < 1 || *r > kMaxMatrixSide || *c > kMaxMatrixSide) {
    Refuse(where + "rows and cols must be integers from 1 to " + std::to_string(kMaxMatrixSide));
  }
  const std::string_view type = Trimmed(node.dt);
  if (type.size() != 1 || std::string_view("ucwsifd").find(type[0]) == std::string_view::npos) {
    Refuse(where + "dt must be one of u, c, w, s, i, f, d (a single-channel matrix of numbers)");
  }
  if (static_cast<int>(node.values.size()) != *r * *c) {
    Refuse(where + "data has " + std::to_string(node.values.size()) +
           " values, rows x cols = " + std::to_string(*r * *c));
  }
  OpenCvMatrix matrix{*r, *c, {}};
  for (const std::string& text : node.values) {
    const auto value = ParseWhole<double>(Trimmed(text));
    if (!value || !std::isfinite(*value)) {
      Refuse(where + "data value '" + std::string(Trimmed(text)) + "' is not a finite number");
    }
    matrix.values.push_back(*value);
  }
  return matrix;
}

// An intrinsics file is a few hundred bytes of ASCII text.
void CheckText(const std::string& text) {
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if ((c < 0x20 && c != '\n' && c != '\r' && c != '\t') || c > 0x7e) {
      Refuse("byte " + std::to_string(c) + " at offset " + std::to_string(i) +
             " is not ASCII text (an OpenCV calibration file is)");
    }
  }
}

// --- YAML ---------------------------------------------------------------------------------

OpenCvNode YamlNode(const YAML::Node& node) {
  OpenCvNode out;
  if (node.IsScalar()) {
    out.scalar = node.Scalar();
    return out;
  }
  if (!node.IsMap() || !node["rows"] || !node["cols"] || !node["data"]) return out;
  out.is_matrix = true;
  const YAML::Node rows = node["rows"], cols = node["cols"], dt = node["dt"], data = node["data"];
  if (!rows.IsScalar() || !cols.IsScalar() || !dt || !dt.IsScalar() || !data.IsSequence()) {
    out.malformed = "an OpenCV matrix needs scalar rows, cols and dt and a data list";
    return out;
  }
  out.rows = rows.Scalar();
  out.cols = cols.Scalar();
  out.dt = dt.Scalar();
  for (const YAML::Node& value : data) {
    if (!value.IsScalar()) {
      out.malformed = "data must be a list of numbers";
      return out;
    }
    out.values.push_back(value.Scalar());
  }
  return out;
}

// " at line N" where yaml-cpp knows the position.
std::string AtLine(const YAML::Mark& mark) {
  return mark.is_null() ? std::string() : " at line " + std::to_string(mark.line + 1);
}

std::map<std::string, OpenCvNode> ParseYaml(std::string text) {
  // OpenCV opens its files with "%YAML:1.0", a directive YAML 1.2 parsers do not accept; the
  // line is blanked so that yaml-cpp's line numbers stay the file's.
  if (text.rfind("%YAML:", 0) == 0) {
    const std::size_t end = text.find('\n');
    text.replace(0, end == std::string::npos ? text.size() : end, "");
  }
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    Refuse("malformed YAML" + AtLine(e.mark) + ": " + e.msg);
  }
  if (!root.IsMap()) Refuse("the top level is not a map of nodes");
  std::map<std::string, OpenCvNode> nodes;
  try {
    for (const auto& entry : root) {
      if (!entry.first.IsScalar()) Refuse("a top-level key is not a name");
      nodes[entry.first.Scalar()] = YamlNode(entry.second);
    }
  } catch (const YAML::Exception& e) {
    Refuse("unreadable YAML" + AtLine(e.mark) + ": " + e.msg);
  }
  return nodes;
}

// --- XML ----------------------------------------------------------------------------------

using XmlDocument = std::unique_ptr<xmlDoc, decltype(&xmlFreeDoc)>;

std::string Name(const xmlNode* node) { return reinterpret_cast<const char*>(node->name); }

// The text of an element's own text children (entities are not expanded: none are expected).
std::string ElementText(const xmlNode* element) {
  std::string text;
  for (const xmlNode* child = element->children; child != nullptr; child = child->next) {
    if (child->type == XML_TEXT_NODE && child->content != nullptr) {
      text += reinterpret_cast<const char*>(child->content);
    }
  }
  return text;
}

bool HasElementChildren(const xmlNode* element) {
  for (const xmlNode* child = element->children; child != nullptr; child = child->next) {
    if (child->type == XML_ELEMENT_NODE) return true;
  }
  return false;
}

std::vector<std::string> Words(std::string_view text) {
  std::vector<std::string> words;
  std::size_t i = 0;
  while ((i = text.find_first_not_of(" \t\r\n", i)) != std::string_view::npos) {
    const std::size_t end = std::min(text.find_first_of(" \t\r\n", i), text.size());
    words.emplace_back(text.substr(i, end - i));
    i = end;
  }
  return words;
}

OpenCvNode XmlNode(const xmlNode* element) {
  OpenCvNode out;
  if (!HasElementChildren(element)) {
    out.scalar = std::string(Trimmed(ElementText(element)));
    return out;
  }
  std::map<std::string, std::string> parts;
  for (const xmlNode* child = element->children; child != nullptr; child = child->next) {
    if (child->type == XML_ELEMENT_NODE) parts[Name(child)] = ElementText(child);
  }
  if (parts.count("rows") == 0 || parts.count("cols") == 0 || parts.count("data") == 0) return out;
  out.is_matrix = true;
  out.rows = parts["rows"];
  out.cols = parts["cols"];
  out.dt = parts["dt"];
  out.values = Words(parts["data"]);
  return out;
}

void InitialiseLibXml() {
  static std::once_flag once;
  std::call_once(once, [] { xmlInitParser(); });
}

std::map<std::string, OpenCvNode> ParseXml(const std::string& text) {
  InitialiseLibXml();
  // No network, no DTD, no entity substitution, and errors as values rather than on stderr.
  const int options = XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING;
  XmlDocument document(
      xmlReadMemory(text.data(), static_cast<int>(text.size()), nullptr, nullptr, options),
      &xmlFreeDoc);
  if (document == nullptr) {
    const xmlError* error = xmlGetLastError();
    std::string what = "malformed XML";
    if (error != nullptr && error->message != nullptr) {
      what +=
          " at line " + std::to_string(error->line) + ": " + std::string(Trimmed(error->message));
    }
    xmlResetLastError();
    Refuse(what);
  }
  const xmlNode* root = xmlDocGetRootElement(document.get());
  if (root == nullptr || Name(root) != "opencv_storage") {
    Refuse("the XML root element is not <opencv_storage>");
  }
  std::map<std::string, OpenCvNode> nodes;
  for (const xmlNode* child = root->children; child != nullptr; child = child->next) {
    if (child->type == XML_ELEMENT_NODE) nodes[Name(child)] = XmlNode(child);
  }
  return nodes;
}

bool LooksLikeXml(const std::string& text) {
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  return first != std::string::npos && text[first] == '<';
}

}  // namespace

OpenCvStorage OpenCvStorage::Read(const std::filesystem::path& path) {
  const std::string source = QuotedPath(path);
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw Error(source + ": no such file (expected an OpenCV calibration YAML or XML)");
  }
  const std::uintmax_t bytes = std::filesystem::file_size(path, error);
  if (error) throw Error(source + ": cannot be read (" + error.message() + ")");
  if (bytes > kMaxFileBytes) throw Error(source + ": larger than 1 MiB: not a calibration file");
  const std::string text = ReadFileBytes(path);
  try {
    CheckText(text);
    return OpenCvStorage(source, LooksLikeXml(text) ? ParseXml(text) : ParseYaml(text));
  } catch (const Refusal& refusal) {
    throw Error(source + ": " + refusal.what);
  }
}

void OpenCvStorage::Fail(const std::string& what) const { throw Error(source_ + ": " + what); }

const OpenCvNode& OpenCvStorage::Find(const std::string& name) const {
  const auto found = nodes_.find(name);
  if (found == nodes_.end()) Fail("missing node '" + name + "'");
  return found->second;
}

int OpenCvStorage::Integer(const std::string& name) const {
  const OpenCvNode& node = Find(name);
  const auto value = node.is_matrix ? std::nullopt : ParseWhole<int>(Trimmed(node.scalar));
  if (!value) Fail("node '" + name + "' must be an integer");
  return *value;
}

OpenCvMatrix OpenCvStorage::Matrix(const std::string& name) const {
  const OpenCvNode& node = Find(name);
  if (!node.is_matrix) Fail("node '" + name + "' must be an OpenCV matrix (!!opencv-matrix)");
  try {
    return MakeMatrix(name, node);
  } catch (const Refusal& refusal) {
    Fail(refusal.what);
  }
}

}  // namespace uwscan::scanner::calibration
