#include "scanner/calibration/calibration_dataset.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "scanner/calibration/calibration_yaml.hpp"
#include "scanner/common/atomic_file.hpp"
#include "scanner/common/error.hpp"
#include "scanner/lasers/scanner_file.hpp"

namespace uwscan::scanner::calibration {
namespace {

namespace fs = std::filesystem;
using namespace calibration_yaml;
using namespace sim::scene_yaml;

bool TakesViews(const std::string& step) { return step == "intrinsics" || step == "viewport"; }
bool TakesStripes(const std::string& step) { return step == "laser" || step == "laser_viewport"; }
bool TakesDots(const std::string& step) { return step == "mems"; }

// Where each field of the manifest was read, so that the checks made once everything is parsed
// (duplicates, files, what a step needs) still name the line. A dataset built in memory has no
// lines; its messages name the manifest it is about to become.
class Locator {
 public:
  explicit Locator(std::string source) : source_(std::move(source)) {}
  void Note(const std::string& field, const YAML::Node& node) {
    if (node.IsDefined() && node.Mark().line >= 0) lines_[field] = node.Mark().line + 1;
  }
  [[noreturn]] void Fail(const std::string& field, const std::string& what) const {
    std::string location = source_;
    const auto line = lines_.find(field);
    if (line != lines_.end()) location += ":" + std::to_string(line->second);
    throw Error(location + ": field '" + field + "': " + what);
  }

 private:
  std::string source_;
  std::map<std::string, int> lines_;
};

std::string Indexed(const std::string& list, size_t i) {
  return list + "[" + std::to_string(i) + "]";
}

std::optional<std::string> ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The size and pixel type a PNG file declares in its IHDR chunk (the first chunk, by the PNG
// standard), read without decoding the image: checking a dataset stays cheap.
struct PngHeader {
  int width = 0, height = 0, bit_depth = 0, colour_type = 0;
};
std::optional<PngHeader> ReadPngHeader(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::array<unsigned char, 26> b{};
  if (!in.read(reinterpret_cast<char*>(b.data()), b.size())) return std::nullopt;
  static constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (!std::equal(kSignature, kSignature + 8, b.begin())) return std::nullopt;
  if (!std::equal(b.begin() + 12, b.begin() + 16, "IHDR")) return std::nullopt;
  auto big_endian = [&](int at) {
    return static_cast<int>((static_cast<unsigned>(b[at]) << 24) | (b[at + 1] << 16) |
                            (b[at + 2] << 8) | b[at + 3]);
  };
  return PngHeader{big_endian(16), big_endian(20), b[24], b[25]};
}

void CheckImage(const CalibrationDataset& d, const std::string& name, const std::string& field,
                const Locator& at) {
  if (name.empty()) at.Fail(field, "expected an image file name");
  const fs::path relative(name);
  if (relative.is_absolute() ||
      std::any_of(relative.begin(), relative.end(), [](const fs::path& p) { return p == ".."; })) {
    at.Fail(field, "image '" + name + "': expected a file name inside the dataset folder");
  }
  const fs::path path = d.ImagePath(name);
  if (!fs::is_regular_file(path)) {
    at.Fail(field, "image '" + name + "' not found (looked for " + path.string() + ")");
  }
  const std::optional<PngHeader> png = ReadPngHeader(path);
  if (!png) at.Fail(field, "image '" + name + "' is not a PNG file (" + path.string() + ")");
  if (png->colour_type != 0 || (png->bit_depth != 8 && png->bit_depth != 16)) {
    at.Fail(field, "image '" + name + "' is not 8- or 16-bit greyscale (PNG colour type " +
                       std::to_string(png->colour_type) + ", " + std::to_string(png->bit_depth) +
                       " bits)");
  }
  if (png->width != d.width_px || png->height != d.height_px) {
    at.Fail(field, "image '" + name + "' is " + std::to_string(png->width) + "x" +
                       std::to_string(png->height) + " px, the manifest's image_size is [" +
                       std::to_string(d.width_px) + ", " + std::to_string(d.height_px) + "]");
  }
}

void CheckStepAndFiles(const CalibrationDataset& d, const Locator& at) {
  const std::vector<std::string>& steps = CalibrationSteps();
  if (std::find(steps.begin(), steps.end(), d.step) == steps.end()) {
    std::string names;
    for (const std::string& s : steps) names += (names.empty() ? "" : ", ") + s;
    at.Fail("step", "got '" + d.step + "', expected one of " + names);
  }
  try {
    d.pattern.Check();
  } catch (const Error& e) {
    at.Fail("pattern", e.what());
  }
  if (d.width_px < 1 || d.height_px < 1) at.Fail("image_size", "expected [width, height] >= 1 px");
  if (d.scanner_file && !fs::is_regular_file(*d.scanner_file)) {
    at.Fail("scanner", "scanner file not found (looked for " + d.scanner_file->string() + ")");
  }
  if (d.truth_file && !fs::is_regular_file(*d.truth_file)) {
    at.Fail("truth", "truth file not found (looked for " + d.truth_file->string() + ")");
  }
}

// Views for the steps that take views, enough planes for the others, and never both.
void CheckViewsOrPlanes(const CalibrationDataset& d, const Locator& at) {
  if (TakesViews(d.step)) {
    if (d.views.size() < 3) {
      at.Fail("views", "a " + d.step + " dataset needs at least 3 views of the pattern, got " +
                           std::to_string(d.views.size()));
    }
    if (!d.planes.empty()) {
      at.Fail("planes", "a " + d.step + " dataset has views only (planes are for laser and mems)");
    }
  } else {
    if (!d.views.empty()) {
      at.Fail("views", "a " + d.step +
                           " dataset has planes only (views are for intrinsics and "
                           "viewport)");
    }
    if (d.planes.size() < 2) {
      at.Fail("planes", "a " + d.step + " dataset needs at least 2 planes (board poses), got " +
                            std::to_string(d.planes.size()));
    }
  }
}

// Stripes on every plane of a stripe step and dots on every plane of a dot step, and neither
// where the step takes none.
void CheckPlaneContents(const std::string& step, const CalibrationDataset::Plane& plane,
                        const std::string& field, const Locator& at) {
  if (TakesStripes(step) && plane.stripes.empty()) {
    at.Fail(field, "a " + step + " dataset needs stripes on every plane; this one has none");
  }
  if (!TakesStripes(step) && !plane.stripes.empty()) {
    at.Fail(field + ".stripes", "stripes belong to laser and laser_viewport datasets, not " + step);
  }
  if (TakesDots(step) && plane.dots.empty()) {
    at.Fail(field, "a mems dataset needs laser dots on every plane; this one has none");
  }
  if (!TakesDots(step) && !plane.dots.empty()) {
    at.Fail(field + ".dots", "dots belong to mems datasets, not " + step);
  }
}

// Each mirror step once on the plane; returns the plane's steps.
std::set<int> CheckMirrorStepsOnce(const CalibrationDataset::Plane& plane, const std::string& field,
                                   const Locator& at) {
  std::set<int> mirror_steps;
  for (size_t k = 0; k < plane.stripes.size(); ++k) {
    const int step = plane.stripes[k].second;
    if (!mirror_steps.insert(step).second) {
      at.Fail(Indexed(field + ".stripes", k) + ".mirror_step",
              "mirror step " + std::to_string(step) + " appears twice on this plane");
    }
  }
  return mirror_steps;
}

// Each voltage pair finite and once on the plane.
void CheckVoltsOnce(const CalibrationDataset::Plane& plane, const std::string& field,
                    const Locator& at) {
  for (size_t k = 0; k < plane.dots.size(); ++k) {
    const Eigen::Vector2d& volts = plane.dots[k].second;
    const std::string dot = Indexed(field + ".dots", k) + ".volts";
    if (!volts.allFinite()) at.Fail(dot, "volts must be finite numbers");
    for (size_t j = 0; j < k; ++j) {
      if (plane.dots[j].second == volts) {
        at.Fail(dot, "voltage pair [" + Shortest(volts.x()) + ", " + Shortest(volts.y()) +
                         "] appears twice on this plane (also dots[" + std::to_string(j) + "])");
      }
    }
  }
}

void CheckPlanes(const CalibrationDataset& d, const Locator& at) {
  std::set<int> all_steps;
  for (size_t p = 0; p < d.planes.size(); ++p) {
    const CalibrationDataset::Plane& plane = d.planes[p];
    const std::string field = Indexed("planes", p);
    CheckPlaneContents(d.step, plane, field, at);
    all_steps.merge(CheckMirrorStepsOnce(plane, field, at));
    CheckVoltsOnce(plane, field, at);
  }
  if (TakesStripes(d.step) && all_steps.size() < 2) {
    at.Fail("planes", "a " + d.step + " dataset needs at least 2 distinct mirror steps");
  }
}

// Every image: named once, present, PNG, greyscale, of image_size.
void CheckImages(const CalibrationDataset& d, const Locator& at) {
  std::map<std::string, std::string> seen;
  auto image = [&](const std::string& name, const std::string& field) {
    const auto [it, added] = seen.emplace(name, field);
    if (!added) at.Fail(field, "image '" + name + "' is also " + it->second);
    CheckImage(d, name, field, at);
  };
  for (size_t v = 0; v < d.views.size(); ++v) image(d.views[v], Indexed("views", v) + ".image");
  for (size_t p = 0; p < d.planes.size(); ++p) {
    const std::string field = Indexed("planes", p);
    image(d.planes[p].pattern_image, field + ".pattern_image");
    for (size_t k = 0; k < d.planes[p].stripes.size(); ++k) {
      image(d.planes[p].stripes[k].first, Indexed(field + ".stripes", k) + ".image");
    }
    for (size_t k = 0; k < d.planes[p].dots.size(); ++k) {
      image(d.planes[p].dots[k].first, Indexed(field + ".dots", k) + ".image");
    }
  }
}

// Everything LoadCalibrationDataset promises to check once the fields are read.
void Validate(const CalibrationDataset& d, const Locator& at) {
  CheckStepAndFiles(d, at);
  CheckViewsOrPlanes(d, at);  // what the step needs, and nothing another step needs
  CheckPlanes(d, at);
  CheckImages(d, at);
}

// --- reading ----------------------------------------------------------------------------------

std::string ReadImageName(const Context& where, const YAML::Node& node, const std::string& key,
                          Locator* at) {
  at->Note(yaml::Enter(where, key).path, node[key]);
  return String(where, node, key);
}

CalibrationDataset::Plane ReadPlane(const Context& where, const YAML::Node& node, Locator* at) {
  yaml::RequireKnownKeys(where, node, {"pattern_image", "stripes", "dots"});
  at->Note(where.path, node);
  CalibrationDataset::Plane plane;
  plane.pattern_image = ReadImageName(where, node, "pattern_image", at);
  auto list = [&](const std::string& key) {
    const YAML::Node items = Has(node, key) ? node[key] : YAML::Node(YAML::NodeType::Sequence);
    if (!items.IsSequence()) yaml::Fail(yaml::Enter(where, key), items, "expected a list");
    at->Note(yaml::Enter(where, key).path, items);
    return items;
  };
  const YAML::Node stripes = list("stripes");
  for (size_t k = 0; k < stripes.size(); ++k) {
    const Context item = Item(yaml::Enter(where, "stripes"), k);
    yaml::RequireKnownKeys(item, stripes[k], {"image", "mirror_step"});
    at->Note(item.path + ".mirror_step", stripes[k]["mirror_step"]);
    plane.stripes.emplace_back(ReadImageName(item, stripes[k], "image", at),
                               yaml::Integer(item, stripes[k], "mirror_step"));
  }
  const YAML::Node dots = list("dots");
  for (size_t k = 0; k < dots.size(); ++k) {
    const Context item = Item(yaml::Enter(where, "dots"), k);
    yaml::RequireKnownKeys(item, dots[k], {"image", "volts"});
    at->Note(item.path + ".volts", dots[k]["volts"]);
    const std::string image = ReadImageName(item, dots[k], "image", at);
    plane.dots.emplace_back(image, yaml::Vector(item, dots[k], "volts", 2));
  }
  return plane;
}

std::optional<fs::path> ReadFile(const Context& where, const YAML::Node& root,
                                 const std::string& key, const fs::path& folder, Locator* at) {
  if (!Has(root, key)) return std::nullopt;
  at->Note(key, root[key]);
  return Resolve(folder, String(where, root, key));
}

CalibrationDataset ParseManifest(const YAML::Node& root, const std::string& source,
                                 const fs::path& folder, Locator* at) {
  const Context top{source, ""};
  yaml::CheckFormat(top, root);
  yaml::RequireKnownKeys(top, root,
                         {"uwscan_format", "dataset", "step", "pattern", "scanner", "image_size",
                          "water_refractive_index", "views", "planes", "truth"});
  const std::string kind = String(top, root, "dataset");
  if (kind != "calibration") {
    FailField(top, root, "dataset", "got '" + kind + "', expected calibration");
  }
  CalibrationDataset d;
  d.folder = folder;
  at->Note("step", root["step"]);
  d.step = String(top, root, "step");
  d.pattern = ReadPattern(yaml::Enter(top, "pattern"), yaml::Child(top, root, "pattern"));
  d.scanner_file = ReadFile(top, root, "scanner", folder, at);
  d.truth_file = ReadFile(top, root, "truth", folder, at);
  const YAML::Node size = yaml::Child(top, root, "image_size");
  at->Note("image_size", size);
  int w = 0, h = 0;
  if (!size.IsSequence() || size.size() != 2 || !YAML::convert<int>::decode(size[0], w) ||
      !YAML::convert<int>::decode(size[1], h) || w < 1 || h < 1) {
    yaml::Fail(yaml::Enter(top, "image_size"), size, "expected [width, height] in pixels, >= 1");
  }
  d.width_px = w;
  d.height_px = h;
  if (Has(root, "water_refractive_index")) {
    const double n = yaml::Number(top, root, "water_refractive_index");
    if (!(n >= 1.0 && n <= 3.0)) {
      FailField(top, root, "water_refractive_index", "expected a refractive index in [1, 3]");
    }
    d.water_refractive_index = n;
  }
  if (Has(root, "views")) {
    const Context list = yaml::Enter(top, "views");
    const YAML::Node views = root["views"];
    if (!views.IsSequence()) yaml::Fail(list, views, "expected a list of {image: file}");
    at->Note("views", views);
    for (size_t v = 0; v < views.size(); ++v) {
      const Context item = Item(list, v);
      yaml::RequireKnownKeys(item, views[v], {"image"});
      d.views.push_back(ReadImageName(item, views[v], "image", at));
    }
  }
  if (Has(root, "planes")) {
    const Context list = yaml::Enter(top, "planes");
    const YAML::Node planes = root["planes"];
    if (!planes.IsSequence()) yaml::Fail(list, planes, "expected a list of planes");
    at->Note("planes", planes);
    for (size_t p = 0; p < planes.size(); ++p)
      d.planes.push_back(ReadPlane(Item(list, p), planes[p], at));
  }
  return d;
}

// --- writing ----------------------------------------------------------------------------------

// A path as the manifest holds it: relative to the folder when inside it.
std::string RelativeToFolder(const fs::path& path, const fs::path& folder) {
  const fs::path relative =
      fs::weakly_canonical(path).lexically_relative(fs::weakly_canonical(folder));
  if (!relative.empty() && *relative.begin() != "..") return relative.generic_string();
  return path.string();
}

std::vector<Eigen::Isometry3d> ReadPoses(const Context& top, const YAML::Node& root,
                                         const std::string& key) {
  std::vector<Eigen::Isometry3d> poses;
  if (!Has(root, key)) return poses;
  const YAML::Node list = root[key];
  const Context where = yaml::Enter(top, key);
  if (!list.IsSequence()) yaml::Fail(where, list, "expected a list of poses");
  for (size_t i = 0; i < list.size(); ++i) {
    // yaml::Pose reads a child; wrap each item so the field path reads "T_C_O_views[3]".
    const Context item = Item(where, i);
    YAML::Node holder(YAML::NodeType::Map);
    holder[item.path] = list[i];
    poses.push_back(yaml::Pose(Context{item.source, ""}, holder, item.path));
  }
  return poses;
}

}  // namespace

const std::vector<std::string>& CalibrationSteps() {
  static const std::vector<std::string> steps = {"intrinsics", "viewport", "laser",
                                                 "laser_viewport", "mems"};
  return steps;
}

CalibrationDataset LoadCalibrationDataset(const fs::path& folder) {
  if (!fs::exists(folder)) throw Error(folder.string() + ": no such calibration dataset folder");
  if (!fs::is_directory(folder)) {
    throw Error(folder.string() + ": not a folder (a calibration dataset is a folder holding " +
                kManifestFileName + " and its images)");
  }
  const fs::path manifest = folder / kManifestFileName;
  const std::optional<std::string> text = ReadText(manifest);
  if (!text || !fs::is_regular_file(manifest)) {
    throw Error(manifest.string() + ": missing or unreadable (every calibration dataset has " +
                "one; format in data/README.md)");
  }
  const YAML::Node root = LoadYaml(*text, manifest.string());
  Locator at(manifest.string());
  CalibrationDataset d = ParseManifest(root, manifest.string(), folder, &at);
  Validate(d, at);
  return d;
}

void WriteCalibrationManifest(const CalibrationDataset& d) {
  const fs::path manifest = d.folder / kManifestFileName;
  if (!fs::is_directory(d.folder)) {
    throw Error(d.folder.string() + ": no such folder to write the manifest into");
  }
  Validate(d, Locator(manifest.string() + " (being written)"));
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "uwscan_format" << YAML::Value << 1;
  out << YAML::Key << "dataset" << YAML::Value << "calibration";
  out << YAML::Key << "step" << YAML::Value << d.step;
  out << YAML::Key << "pattern" << YAML::Value;
  EmitPattern(out, d.pattern);
  if (d.scanner_file) {
    out << YAML::Key << "scanner" << YAML::Value << RelativeToFolder(*d.scanner_file, d.folder);
  }
  out << YAML::Key << "image_size" << YAML::Value << YAML::Flow << YAML::BeginSeq << d.width_px
      << d.height_px << YAML::EndSeq;
  if (d.water_refractive_index) {
    out << YAML::Key << "water_refractive_index" << YAML::Value << *d.water_refractive_index;
  }
  if (!d.views.empty()) {
    out << YAML::Key << "views" << YAML::Value << YAML::BeginSeq;
    for (const std::string& view : d.views) {
      out << YAML::Flow << YAML::BeginMap << YAML::Key << "image" << YAML::Value << view
          << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  if (!d.planes.empty()) {
    out << YAML::Key << "planes" << YAML::Value << YAML::BeginSeq;
    for (const CalibrationDataset::Plane& plane : d.planes) {
      out << YAML::BeginMap << YAML::Key << "pattern_image" << YAML::Value << plane.pattern_image;
      if (!plane.stripes.empty()) {
        out << YAML::Key << "stripes" << YAML::Value << YAML::BeginSeq;
        for (const auto& [image, step] : plane.stripes) {
          out << YAML::Flow << YAML::BeginMap << YAML::Key << "image" << YAML::Value << image
              << YAML::Key << "mirror_step" << YAML::Value << step << YAML::EndMap;
        }
        out << YAML::EndSeq;
      }
      if (!plane.dots.empty()) {
        out << YAML::Key << "dots" << YAML::Value << YAML::BeginSeq;
        for (const auto& [image, volts] : plane.dots) {
          out << YAML::Flow << YAML::BeginMap << YAML::Key << "image" << YAML::Value << image
              << YAML::Key << "volts" << YAML::Value << YAML::Flow << YAML::BeginSeq
              << Shortest(volts.x()) << Shortest(volts.y()) << YAML::EndSeq << YAML::EndMap;
        }
        out << YAML::EndSeq;
      }
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  if (d.truth_file) {
    out << YAML::Key << "truth" << YAML::Value << RelativeToFolder(*d.truth_file, d.folder);
  }
  out << YAML::EndMap;
  if (!out.good()) throw Error(manifest.string() + ": cannot emit YAML: " + out.GetLastError());
  WriteFileAtomically(manifest, std::string(out.c_str()) + "\n");
}

DatasetTruth LoadDatasetTruth(const fs::path& path) {
  const std::optional<std::string> text = ReadText(path);
  if (!text || !fs::is_regular_file(path)) throw Error(path.string() + ": cannot open truth file");
  const YAML::Node root = LoadYaml(*text, path.string());
  const Context top{path.string(), ""};
  yaml::CheckFormat(top, root);
  yaml::RequireKnownKeys(top, root,
                         {"uwscan_format", "dataset", "scanner", "T_C_O_views", "T_C_O_planes"});
  const std::string kind = String(top, root, "dataset");
  if (kind != "calibration_truth") {
    FailField(top, root, "dataset", "got '" + kind + "', expected calibration_truth");
  }
  DatasetTruth truth;
  truth.scanner = ParseScanner(String(top, root, "scanner"), path.string() + " (scanner)");
  truth.T_C_O_views = ReadPoses(top, root, "T_C_O_views");
  truth.T_C_O_planes = ReadPoses(top, root, "T_C_O_planes");
  return truth;
}

void WriteDatasetTruth(const fs::path& path, const DatasetTruth& truth) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "uwscan_format" << YAML::Value << 1;
  out << YAML::Key << "dataset" << YAML::Value << "calibration_truth";
  out << YAML::Key << "scanner" << YAML::Value << YAML::Literal << ScannerToYaml(truth.scanner);
  for (const auto& [key, poses] : {std::pair{"T_C_O_views", &truth.T_C_O_views},
                                   std::pair{"T_C_O_planes", &truth.T_C_O_planes}}) {
    out << YAML::Key << key << YAML::Value << YAML::BeginSeq;
    for (const Eigen::Isometry3d& T : *poses) EmitPose(out, T);
    out << YAML::EndSeq;
  }
  out << YAML::EndMap;
  if (!out.good()) throw Error(path.string() + ": cannot emit YAML: " + out.GetLastError());
  WriteFileAtomically(path, std::string(out.c_str()) + "\n");
}

}  // namespace uwscan::scanner::calibration
