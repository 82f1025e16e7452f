#include "scanner/sim/scene_objects.hpp"

#include <functional>
#include <map>
#include <optional>
#include <string>

#include "scanner/common/error.hpp"
#include "scanner/sim/imr_objects.hpp"
#include "scanner/sim/scene_fields.hpp"

namespace uwscan::scanner::sim {
namespace {

using namespace scene_yaml;

constexpr ObjectShape kAllShapes[] = {
    ObjectShape::kPlane,  ObjectShape::kBox,   ObjectShape::kSphere, ObjectShape::kCylinder,
    ObjectShape::kMesh,   ObjectShape::kPipe,  ObjectShape::kElbow,  ObjectShape::kTee,
    ObjectShape::kFlange, ObjectShape::kValve, ObjectShape::kGauge};

std::optional<ObjectShape> ShapeFromString(const std::string& name) {
  for (const ObjectShape s : kAllShapes) {
    if (name == ToString(s)) return s;
  }
  return std::nullopt;
}

// Keys every object may carry, plus those of its shape.
void RequireObjectKeys(const Context& where, const YAML::Node& node, ObjectShape shape) {
  switch (shape) {
    case ObjectShape::kPlane:
    case ObjectShape::kBox:
      return yaml::RequireKnownKeys(where, node,
                                    {"name", "shape", "pose", "reflectance", "size_m"});
    case ObjectShape::kSphere:
      return yaml::RequireKnownKeys(where, node,
                                    {"name", "shape", "pose", "reflectance", "radius_m"});
    case ObjectShape::kCylinder:
      return yaml::RequireKnownKeys(
          where, node,
          {"name", "shape", "pose", "reflectance", "chord_error_m", "radius_m", "length_m"});
    case ObjectShape::kMesh:
      return yaml::RequireKnownKeys(where, node,
                                    {"name", "shape", "pose", "reflectance", "file", "scale"});
    case ObjectShape::kPipe:
      return yaml::RequireKnownKeys(
          where, node,
          {"name", "shape", "pose", "reflectance", "chord_error_m", "outer_radius_m", "wall_m",
           "length_m", "dent_radius_m", "dent_depth_m", "dent_angle_rad", "dent_position_m"});
    case ObjectShape::kElbow:
      return yaml::RequireKnownKeys(
          where, node,
          {"name", "shape", "pose", "reflectance", "chord_error_m", "outer_radius_m", "wall_m",
           "bend_radius_m", "bend_angle_rad"});
    case ObjectShape::kTee:
      return yaml::RequireKnownKeys(
          where, node,
          {"name", "shape", "pose", "reflectance", "chord_error_m", "outer_radius_m", "wall_m",
           "run_length_m", "branch_length_m"});
    case ObjectShape::kFlange:
      return yaml::RequireKnownKeys(
          where, node,
          {"name", "shape", "pose", "reflectance", "chord_error_m", "outer_radius_m", "wall_m",
           "length_m", "flange_radius_m", "flange_thickness_m", "bolts", "bolt_head_radius_m",
           "bolt_head_height_m", "missing_bolts"});
    case ObjectShape::kValve:
      return yaml::RequireKnownKeys(
          where, node,
          {"name", "shape", "pose", "reflectance", "chord_error_m", "outer_radius_m", "wall_m",
           "body_radius_m", "body_length_m", "stub_length_m", "stem_radius_m", "stem_length_m",
           "handle", "handle_radius_m"});
    case ObjectShape::kGauge:
      return yaml::RequireKnownKeys(where, node,
                                    {"name", "shape", "pose", "reflectance", "length_m"});
  }
}

// The fields of one object's mapping, as the readers of its geometry take them.
struct ObjectFields {
  const Context& where;
  const YAML::Node& node;
  double chord_error_m;

  // A length in metres, > 0; required unless a fallback is given.
  double Length(const char* key, std::optional<double> fallback = std::nullopt) const {
    return Number(where, node, key, Range::kPositive, fallback);
  }
  // The size_m field: n positive lengths.
  Eigen::VectorXd Sizes(int n) const {
    const Eigen::VectorXd v = yaml::Vector(where, node, "size_m", n);
    if (!(v.array() > 0.0).all()) FailField(where, node, "size_m", "expected positive lengths");
    return v;
  }
  // The mesh `make` builds from the fields read, a failure reported at the object.
  TriangleMesh Built(const std::function<TriangleMesh()>& make) const {
    TriangleMesh mesh;
    Checked(where, node, [&] { mesh = make(); });
    return mesh;
  }
};

// A mesh file, scaled.
TriangleMesh ReadMeshFile(const ObjectFields& f, const std::filesystem::path& base_dir) {
  const std::filesystem::path file = Resolve(base_dir, String(f.where, f.node, "file"));
  const double scale = Number(f.where, f.node, "scale", Range::kPositive, 1.0);
  TriangleMesh mesh;
  try {
    mesh = LoadMesh(file);
  } catch (const Error& e) {
    FailField(f.where, f.node, "file", e.what());
  }
  for (Eigen::Vector3d& v : mesh.vertices) v *= scale;
  return mesh;
}

TriangleMesh ReadPipe(const ObjectFields& f) {
  PipeShape s;
  s.outer_radius_m = f.Length("outer_radius_m", s.outer_radius_m);
  s.wall_m = f.Length("wall_m", s.wall_m);
  s.length_m = f.Length("length_m", s.length_m);
  s.dent_radius_m = Number(f.where, f.node, "dent_radius_m", Range::kNonNegative, 0.0);
  s.dent_depth_m = Number(f.where, f.node, "dent_depth_m", Range::kNonNegative, 0.0);
  s.dent_angle_rad = yaml::NumberOr(f.where, f.node, "dent_angle_rad", 0.0);
  s.dent_position_m = yaml::NumberOr(f.where, f.node, "dent_position_m", 0.0);
  return f.Built([&] { return MakePipe(s, f.chord_error_m); });
}

TriangleMesh ReadElbow(const ObjectFields& f) {
  ElbowShape s;
  s.outer_radius_m = f.Length("outer_radius_m", s.outer_radius_m);
  s.wall_m = f.Length("wall_m", s.wall_m);
  s.bend_radius_m = f.Length("bend_radius_m", s.bend_radius_m);
  s.bend_angle_rad = Number(f.where, f.node, "bend_angle_rad", Range::kPositive, s.bend_angle_rad);
  return f.Built([&] { return MakeElbow(s, f.chord_error_m); });
}

TriangleMesh ReadTee(const ObjectFields& f) {
  TeeShape s;
  s.outer_radius_m = f.Length("outer_radius_m", s.outer_radius_m);
  s.wall_m = f.Length("wall_m", s.wall_m);
  s.run_length_m = f.Length("run_length_m", s.run_length_m);
  s.branch_length_m = f.Length("branch_length_m", s.branch_length_m);
  return f.Built([&] { return MakeTee(s, f.chord_error_m); });
}

TriangleMesh ReadFlange(const ObjectFields& f) {
  FlangeShape s;
  s.outer_radius_m = f.Length("outer_radius_m", s.outer_radius_m);
  s.wall_m = f.Length("wall_m", s.wall_m);
  s.length_m = f.Length("length_m", s.length_m);
  s.flange_radius_m = f.Length("flange_radius_m", s.flange_radius_m);
  s.flange_thickness_m = f.Length("flange_thickness_m", s.flange_thickness_m);
  s.bolts = Integer(f.where, f.node, "bolts", 0, s.bolts);
  s.bolt_head_radius_m = f.Length("bolt_head_radius_m", s.bolt_head_radius_m);
  s.bolt_head_height_m = f.Length("bolt_head_height_m", s.bolt_head_height_m);
  if (Has(f.node, "missing_bolts")) {
    const YAML::Node list = f.node["missing_bolts"];
    if (!list.IsSequence())
      FailField(f.where, f.node, "missing_bolts", "expected a list of bolt indices");
    for (std::size_t i = 0; i < list.size(); ++i) {
      int k = 0;
      if (!list[i].IsScalar() || !YAML::convert<int>::decode(list[i], k))
        yaml::Fail(Item(yaml::Enter(f.where, "missing_bolts"), i), list[i], "expected an integer");
      s.missing_bolts.push_back(k);
    }
  }
  return f.Built([&] { return MakeFlange(s, f.chord_error_m); });
}

// The valve's handle: wheel or lever, `fallback` when not given.
ValveHandle ReadHandle(const ObjectFields& f, ValveHandle fallback) {
  if (!Has(f.node, "handle")) return fallback;
  const std::string handle = String(f.where, f.node, "handle");
  if (handle == "wheel") return ValveHandle::kWheel;
  if (handle == "lever") return ValveHandle::kLever;
  FailField(f.where, f.node, "handle", "got '" + handle + "', expected wheel or lever");
}

TriangleMesh ReadValve(const ObjectFields& f) {
  ValveShape s;
  s.outer_radius_m = f.Length("outer_radius_m", s.outer_radius_m);
  s.wall_m = f.Length("wall_m", s.wall_m);
  s.body_radius_m = f.Length("body_radius_m", s.body_radius_m);
  s.body_length_m = f.Length("body_length_m", s.body_length_m);
  s.stub_length_m = f.Length("stub_length_m", s.stub_length_m);
  s.stem_radius_m = f.Length("stem_radius_m", s.stem_radius_m);
  s.stem_length_m = f.Length("stem_length_m", s.stem_length_m);
  s.handle_radius_m = f.Length("handle_radius_m", s.handle_radius_m);
  s.handle = ReadHandle(f, s.handle);
  return f.Built([&] { return MakeValve(s, f.chord_error_m); });
}

// The geometry of one object in {O}, from the fields of its shape.
void ReadGeometry(const Context& where, const YAML::Node& node,
                  const std::filesystem::path& base_dir, SceneObject* object) {
  const ObjectFields f{where, node,
                       Number(where, node, "chord_error_m", Range::kPositive, kDefaultChordErrorM)};
  switch (object->shape) {
    case ObjectShape::kPlane: {
      const Eigen::VectorXd s = f.Sizes(2);
      object->mesh = MakeRectangle(s[0], s[1]);
      return;
    }
    case ObjectShape::kBox:
      object->mesh = MakeBox(f.Sizes(3));
      return;
    case ObjectShape::kSphere:
      object->sphere_radius_m = f.Length("radius_m");
      return;
    case ObjectShape::kCylinder: {
      const double r = f.Length("radius_m");
      object->mesh = MakeCylinder(r, f.Length("length_m"), f.chord_error_m);
      return;
    }
    case ObjectShape::kMesh:
      object->mesh = ReadMeshFile(f, base_dir);
      return;
    case ObjectShape::kPipe:
      object->mesh = ReadPipe(f);
      return;
    case ObjectShape::kElbow:
      object->mesh = ReadElbow(f);
      return;
    case ObjectShape::kTee:
      object->mesh = ReadTee(f);
      return;
    case ObjectShape::kFlange:
      object->mesh = ReadFlange(f);
      return;
    case ObjectShape::kValve:
      object->mesh = ReadValve(f);
      return;
    case ObjectShape::kGauge:
      object->gauge_length_m = f.Length("length_m");
      object->mesh = MakeGaugeBlock(object->gauge_length_m);
      return;
  }
}

}  // namespace

std::vector<SceneObject> ReadSceneObjects(const Context& where, const YAML::Node& node,
                                          const std::filesystem::path& base_dir) {
  if (!node.IsSequence() || node.size() == 0) {
    yaml::Fail(where, node, "expected a list of at least one object");
  }
  std::vector<SceneObject> objects;
  std::map<std::string, size_t> names;
  for (size_t i = 0; i < node.size(); ++i) {
    const Context at = Item(where, i);
    const YAML::Node item = node[i];
    if (!item.IsMap()) yaml::Fail(at, item, "expected a mapping with at least 'shape'");
    SceneObject object;
    const std::string shape_name = String(at, item, "shape");
    const std::optional<ObjectShape> shape = ShapeFromString(shape_name);
    if (!shape) {
      std::string all;
      for (const ObjectShape s : kAllShapes)
        all += std::string(all.empty() ? "" : ", ") + ToString(s);
      FailField(at, item, "shape", "got '" + shape_name + "', expected one of " + all);
    }
    object.shape = *shape;
    RequireObjectKeys(at, item, object.shape);
    object.name =
        Has(item, "name") ? String(at, item, "name") : shape_name + "_" + std::to_string(i);
    const auto [previous, added] = names.emplace(object.name, i);
    if (!added) {
      FailField(at, item, "name",
                "duplicate object name '" + object.name + "' (also " + where.path + "[" +
                    std::to_string(previous->second) + "])");
    }
    if (Has(item, "pose")) object.T_W_O = yaml::Pose(at, item, "pose");
    object.reflectance = Number(at, item, "reflectance", Range::kUnitInterval, object.reflectance);
    ReadGeometry(at, item, base_dir, &object);
    objects.push_back(std::move(object));
  }
  return objects;
}

}  // namespace uwscan::scanner::sim
