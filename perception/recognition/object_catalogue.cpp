#include "perception/recognition/object_catalogue.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include "perception/cloud/cloud_io.hpp"
#include "perception/recognition/cloud_surface.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/file_bytes.hpp"
#include "scanner/common/ply_reader.hpp"
#include "scanner/common/yaml_fields.hpp"
#include "scanner/sim/imr_objects.hpp"

namespace uwscan::perception {
namespace {

namespace sim = scanner::sim;
namespace yaml = scanner::yaml;

// A grasp at `origin_O`, approaching along `approach_O`, fingers closing along `closing_O`
// (made orthogonal to the approach).
GraspFrame Grasp(const std::string& name, const Eigen::Vector3d& origin_O,
                 const Eigen::Vector3d& approach_O, const Eigen::Vector3d& closing_O) {
  const Eigen::Vector3d z = approach_O.normalized();
  const Eigen::Vector3d x = (closing_O - closing_O.dot(z) * z).normalized();
  GraspFrame g;
  g.name = name;
  g.T_O_G.linear().col(0) = x;
  g.T_O_G.linear().col(1) = z.cross(x);
  g.T_O_G.linear().col(2) = z;
  g.T_O_G.translation() = origin_O;
  return g;
}

ObjectSource Pipe() {
  sim::PipeShape shape;  // 100 mm pipe, 0.5 m long
  ObjectSource o{"pipe", "procedural: pipe", sim::MakePipe(shape), {}, std::nullopt};
  // Around the middle of the body, from any side (the pipe's symmetry makes them one).
  o.grasps.push_back(Grasp("body", Eigen::Vector3d(0, -shape.outer_radius_m, 0),
                           Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(1, 0, 0)));
  // Symmetries declared by construction, exact where detection from surface samples is
  // within a fraction of a degree (and such a fraction, doubled by a half turn, counts as
  // pose error). Continuous about the axis, a half turn end for end about x.
  o.symmetries = std::vector<SymmetryAxis>{{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0},
                                           {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), 2}};
  return o;
}

ObjectSource Elbow() {
  sim::ElbowShape shape;
  ObjectSource o{"elbow", "procedural: elbow", sim::MakeElbow(shape), {}, std::nullopt};
  // Mid-bend on the outside of the bend, approaching towards the bend's centre.
  const double a = 0.5 * shape.bend_angle_rad, r = shape.bend_radius_m;
  const Eigen::Vector3d centre(r, 0, 0);
  const Eigen::Vector3d on_line(r * (1.0 - std::cos(a)), 0, r * std::sin(a));
  const Eigen::Vector3d outward = (on_line - centre).normalized();
  o.grasps.push_back(
      Grasp("bend", on_line + shape.outer_radius_m * outward, -outward, Eigen::Vector3d(0, 1, 0)));
  // A half turn about the bend's bisector (through the bend's centre and the middle of the
  // centre line) swaps the two ends.
  o.symmetries = std::vector<SymmetryAxis>{{centre, outward, 2}};
  return o;
}

ObjectSource Tee() {
  sim::TeeShape shape;
  ObjectSource o{"tee", "procedural: tee", sim::MakeTee(shape), {}, std::nullopt};
  // On the run, a quarter of its length from the branch, approaching from the side opposite it.
  o.grasps.push_back(Grasp("run",
                           Eigen::Vector3d(-shape.outer_radius_m, 0, 0.25 * shape.run_length_m),
                           Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0)));
  // A half turn about the branch swaps the run's ends.
  o.symmetries = std::vector<SymmetryAxis>{{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), 2}};
  return o;
}

ObjectSource Flange() {
  sim::FlangeShape shape;
  ObjectSource o{"flange", "procedural: flange", sim::MakeFlange(shape), {}, std::nullopt};
  // The rim, pinched across the flange's thickness, approaching radially.
  const double z = 0.5 * shape.length_m - 0.5 * shape.flange_thickness_m;
  o.grasps.push_back(Grasp("rim", Eigen::Vector3d(shape.flange_radius_m, 0, z),
                           Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(0, 0, 1)));
  // The bolts make it N-fold, not continuous: declared, as it is by construction.
  o.symmetries =
      std::vector<SymmetryAxis>{{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), shape.bolts}};
  return o;
}

ObjectSource Valve(sim::ValveHandle handle) {
  sim::ValveShape shape;
  shape.handle = handle;
  const bool wheel = handle == sim::ValveHandle::kWheel;
  const std::string id = wheel ? "valve_wheel" : "valve_lever";
  ObjectSource o{id, "procedural: " + id, sim::MakeValve(shape), {}, std::nullopt};
  // The handle from above: the wheel's rim, or the lever's end, fingers across the bar.
  o.grasps.push_back(Grasp("handle", Eigen::Vector3d(0, shape.stem_length_m, shape.handle_radius_m),
                           Eigen::Vector3d(0, -1, 0),
                           wheel ? Eigen::Vector3d(0, 0, 1) : Eigen::Vector3d(1, 0, 0)));
  // The wheel (two crossed spokes) turns a half turn about the stem with the body; the
  // one-sided lever has no symmetry.
  o.symmetries =
      wheel ? std::vector<SymmetryAxis>{{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(), 2}}
            : std::vector<SymmetryAxis>{};
  return o;
}

ObjectSource Panel() {
  sim::PanelShape shape;
  ObjectSource o{"panel", "procedural: panel", sim::MakePanel(shape), {}, std::nullopt};
  // A handle's bar from the front, fingers closing across it.
  o.grasps.push_back(Grasp("handle",
                           Eigen::Vector3d(shape.handle_offset_m, 0, shape.handle_depth_m),
                           Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(1, 0, 0)));
  // A half turn about the front face's normal swaps the handles.
  o.symmetries = std::vector<SymmetryAxis>{{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 2}};
  return o;
}

const std::map<std::string, ObjectSource (*)()>& Catalogue() {
  static const std::map<std::string, ObjectSource (*)()> catalogue = {
      {"pipe", &Pipe},
      {"elbow", &Elbow},
      {"tee", &Tee},
      {"flange", &Flange},
      {"panel", &Panel},
      {"valve_wheel", [] { return Valve(sim::ValveHandle::kWheel); }},
      {"valve_lever", [] { return Valve(sim::ValveHandle::kLever); }},
  };
  return catalogue;
}

}  // namespace

std::vector<std::string> CatalogueNames() {
  std::vector<std::string> names;
  for (const auto& [name, make] : Catalogue()) names.push_back(name);
  return names;
}

ObjectSource CatalogueObject(const std::string& name) {
  const auto it = Catalogue().find(name);
  if (it == Catalogue().end()) {
    std::string known;
    for (const std::string& n : CatalogueNames()) known += (known.empty() ? "" : ", ") + n;
    const std::filesystem::path path(name);
    if (path.has_extension() || path.has_parent_path())  // meant as a file
      throw Error("'" + name + "': no such file (nor a procedural object: " + known + ")");
    throw Error("'" + name + "' is neither a mesh file nor a procedural object (" + known + ")");
  }
  return it->second();
}

std::filesystem::path GraspSidecarPath(const std::filesystem::path& mesh_path) {
  std::filesystem::path sidecar = mesh_path;
  sidecar.replace_extension(".grasps.yaml");
  return sidecar;
}

namespace {

// Refuses an object no IMR task handles, with a hint about the units that would make sense of it.
void RequireObjectSize(double diagonal_m, double units_to_m, const std::string& name) {
  if (diagonal_m <= kLargestObject_m && diagonal_m >= kSmallestObject_m) return;
  char size[64];
  std::snprintf(size, sizeof size, "%.4g m", diagonal_m);
  const std::string hint = diagonal_m > kLargestObject_m
                               ? (units_to_m >= 1.0 ? "is it in millimetres? give --units mm"
                                                    : "check the mesh's units (--units)")
                               : (units_to_m < 1.0 ? "is it in metres? give --units m"
                                                   : "check the mesh's units (--units)");
  throw Error(
      name + ": the object is " + size +
      " across (bounding box diagonal), outside the 5 mm to 10 m an object can be: " + hint);
}

void RequireUnits(double units_to_m, const std::filesystem::path& path) {
  if (!(units_to_m > 0.0) || !std::isfinite(units_to_m))
    throw Error(path.string() + ": units_to_m must be finite and > 0");
}

// The grasps, symmetries and id of the sidecar beside `path`, when there is one.
void ReadSidecar(const std::filesystem::path& path, ObjectSource& o);

}  // namespace

bool IsCloudFile(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (extension == ".pcd" || extension == ".xyz") return true;
  // Not opened unless a regular file: a pipe with no writer would block (LoadMesh says why not).
  return extension == ".ply" && IsRegularFile(path) && scanner::PlyFaceCount(path).value_or(0) <= 0;
}

ObjectSource MeshObject(const std::filesystem::path& mesh_path, double units_to_m) {
  RequireUnits(units_to_m, mesh_path);
  ObjectSource o;
  o.id = mesh_path.stem().string();
  o.source = mesh_path.string();
  o.mesh = scanner::LoadMesh(mesh_path);
  for (Eigen::Vector3d& v : o.mesh.vertices) v *= units_to_m;
  RequireObjectSize(o.mesh.BoundingBoxDiagonal(), units_to_m, mesh_path.string());
  ReadSidecar(mesh_path, o);
  return o;
}

ObjectSource CloudObject(const std::filesystem::path& cloud_path, double units_to_m) {
  RequireUnits(units_to_m, cloud_path);
  PointCloud cloud = ReadCloud(cloud_path);
  cloud.origin *= units_to_m;
  for (Eigen::Vector3f& p : cloud.points) p *= static_cast<float>(units_to_m);
  RequireObjectSize(BoundingBoxDiagonal(cloud), units_to_m, cloud_path.string());
  ObjectSource o;
  o.id = cloud_path.stem().string();
  o.source = cloud_path.string() + " (a scan: its points as discs)";
  try {
    o.mesh = CloudSurface(cloud);
  } catch (const Error& e) {
    throw Error(cloud_path.string() + ": " + e.what());
  }
  ReadSidecar(cloud_path, o);
  return o;
}

namespace {

void ReadSidecar(const std::filesystem::path& path, ObjectSource& o) {
  const std::filesystem::path sidecar = GraspSidecarPath(path);
  if (!std::filesystem::exists(sidecar)) return;
  RequireRegularFile(sidecar, sidecar.string());
  std::ifstream in(sidecar);
  std::ostringstream text;
  text << in.rdbuf();
  YAML::Node root;
  try {
    root = YAML::Load(text.str());
  } catch (const YAML::Exception& e) {
    throw Error(sidecar.string() + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  const yaml::Context where{sidecar.string(), ""};
  yaml::CheckFormat(where, root);
  yaml::RequireKnownKeys(where, root, {"uwscan_format", "id", "grasps", "symmetries"});
  if (root["id"]) o.id = yaml::Text(where, root, "id");
  if (root["grasps"]) {
    const YAML::Node grasps = root["grasps"];
    for (std::size_t i = 0; i < grasps.size(); ++i) {
      const yaml::Context at = yaml::Enter(where, "grasps[" + std::to_string(i) + "]");
      yaml::RequireKnownKeys(at, grasps[i], {"name", "pose"});
      o.grasps.push_back({yaml::Text(at, grasps[i], "name"), yaml::Pose(at, grasps[i], "pose")});
    }
  }
  if (root["symmetries"]) {
    std::vector<SymmetryAxis> axes;
    const YAML::Node symmetries = root["symmetries"];
    for (std::size_t i = 0; i < symmetries.size(); ++i) {
      const yaml::Context at = yaml::Enter(where, "symmetries[" + std::to_string(i) + "]");
      yaml::RequireKnownKeys(at, symmetries[i], {"point_m", "axis", "order"});
      SymmetryAxis s;
      s.point_O = yaml::Vector3(at, symmetries[i], "point_m");
      const Eigen::Vector3d axis = yaml::Vector3(at, symmetries[i], "axis");
      s.order = yaml::Integer(at, symmetries[i], "order");
      if (!(axis.norm() > 0.0)) yaml::Fail(at, symmetries[i], "axis must not be zero");
      if (s.order < 0 || s.order == 1) yaml::Fail(at, symmetries[i], "order must be 0 or >= 2");
      s.axis_O = axis.normalized();
      axes.push_back(s);
    }
    o.symmetries = axes;
  }
}

}  // namespace

}  // namespace uwscan::perception
