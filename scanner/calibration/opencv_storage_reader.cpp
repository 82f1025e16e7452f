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

// The checks every matrix passes, whichever syntax carried it.
OpenCvMatrix MakeMatrix(const std::string& name, std::string_view rows, std::string_view cols,
                        std::string_view dt, const std::vector<std::string_view>& values) {
  const std::string node = "node '" + name + "': ";
  const auto r = ParseWhole<int>(Trimmed(rows));
  const auto c = ParseWhole<int>(Trimmed(cols));
  if (!r || !c || *r < 1 || *c < 1 || *r > kMaxMatrixSide || *c > kMaxMatrixSide) {
    Refuse(node + "rows and cols must be integers from 1 to " + std::to_string(kMaxMatrixSide));
  }
  const std::string_view type = Trimmed(dt);
  if (type != "d" && type != "f") Refuse(node + "dt must be 'd' or 'f' (a matrix of numbers)");
  if (static_cast<int>(values.size()) != *r * *c) {
    Refuse(node + "data has " + std::to_string(values.size()) + " values, rows x cols = " +
           std::to_string(*r * *c));
  }
  OpenCvMatrix matrix{*r, *c, {}};
  for (const std::string_view text : values) {
    const auto value = ParseWhole<double>(Trimmed(text));
    if (!value || !std::isfinite(*value)) {
      Refuse(node + "data value '" + std::string(Trimmed(text)) + "' is not a finite number");
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

OpenCvNode YamlNode(const std::string& name, const YAML::Node& node) {
  OpenCvNode out;
  if (node.IsScalar()) {
    out.scalar = node.Scalar();
  } else if (node.IsMap() && node["rows"] && node["cols"] && node["data"]) {
    const YAML::Node data = node["data"];
    const YAML::Node dt = node["dt"];
    if (!node["rows"].IsScalar() || !node["cols"].IsScalar() || !dt || !dt.IsScalar() ||
        !data.IsSequence()) {
      Refuse("node '" + name + "': an OpenCV matrix needs scalar rows, cols and dt and a data list");
    }
    if (data.size() > kMaxMatrixSide * kMaxMatrixSide) {
      Refuse("node '" + name + "': data has more values than a calibration matrix");
    }
    std::vector<std::string> texts;
    for (const YAML::Node& value : data) {
      if (!value.IsScalar()) Refuse("node '" + name + "': data must be a list of numbers");
      texts.push_back(value.Scalar());
    }
    const std::vector<std::string_view> views(texts.begin(), texts.end());
    out.is_matrix = true;
    out.matrix = MakeMatrix(name, node["rows"].Scalar(), node["cols"].Scalar(), dt.Scalar(), views);
  }
  return out;
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
    Refuse("malformed YAML at line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (!root.IsMap()) Refuse("the top level is not a map of nodes");
  std::map<std::string, OpenCvNode> nodes;
  try {
    for (const auto& entry : root) {
      if (!entry.first.IsScalar()) Refuse("a top-level key is not a name");
      const std::string name = entry.first.Scalar();
      nodes[name] = YamlNode(name, entry.second);
    }
  } catch (const YAML::Exception& e) {
    Refuse("unreadable YAML at line " + std::to_string(e.mark.line + 1) + ": " + e.msg);
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

std::vector<std::string_view> Words(std::string_view text) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (true) {
    i = text.find_first_not_of(" \t\r\n", i);
    if (i == std::string_view::npos) return words;
    const std::size_t end = std::min(text.find_first_of(" \t\r\n", i), text.size());
    words.push_back(text.substr(i, end - i));
    if (words.size() > kMaxMatrixSide * kMaxMatrixSide) return words;
    i = end;
  }
}

OpenCvNode XmlNode(const std::string& name, const xmlNode* element) {
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
  const std::string data = parts["data"];
  out.is_matrix = true;
  out.matrix = MakeMatrix(name, parts["rows"], parts["cols"], parts["dt"], Words(data));
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
      what += " at line " + std::to_string(error->line) + ": " + std::string(Trimmed(error->message));
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
    if (child->type == XML_ELEMENT_NODE) nodes[Name(child)] = XmlNode(Name(child), child);
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
  if (std::filesystem::file_size(path, error) > kMaxFileBytes) {
    throw Error(source + ": larger than 1 MiB: not a calibration file");
  }
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
  return node.matrix;
}

}  // namespace uwscan::scanner::calibration
