#include "scanner/sim/scene_objects.hpp"

#include <map>

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
      return yaml::RequireKnownKeys(where, node,
                                    {"name", "shape", "pose", "reflectance", "chord_error_m",
                                     "outer_radius_m", "wall_m", "length_m"});
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
           "bolt_head_height_m"});
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

// The geometry of one object in {O}, from the fields of its shape.
void ReadGeometry(const Context& where, const YAML::Node& node,
                  const std::filesystem::path& base_dir, SceneObject* object) {
  const double chord = Number(where, node, "chord_error_m", Range::kPositive, kDefaultChordErrorM);
  auto length = [&](const char* key, double fallback) {
    return Number(where, node, key, Range::kPositive, fallback);
  };
  auto sizes = [&](int n) {
    const Eigen::VectorXd v = yaml::Vector(where, node, "size_m", n);
    if (!(v.array() > 0.0).all()) FailField(where, node, "size_m", "expected positive lengths");
    return v;
  };
  switch (object->shape) {
    case ObjectShape::kPlane: {
      const Eigen::VectorXd s = sizes(2);
      object->mesh = MakeRectangle(s[0], s[1]);
      return;
    }
    case ObjectShape::kBox:
      object->mesh = MakeBox(sizes(3));
      return;
    case ObjectShape::kSphere:
      object->sphere_radius_m = Number(where, node, "radius_m", Range::kPositive);
      return;
    case ObjectShape::kCylinder: {
      const double r = Number(where, node, "radius_m", Range::kPositive);
      object->mesh = MakeCylinder(r, Number(where, node, "length_m", Range::kPositive), chord);
      return;
    }
    case ObjectShape::kMesh: {
      const std::filesystem::path file = Resolve(base_dir, String(where, node, "file"));
      const double scale = Number(where, node, "scale", Range::kPositive, 1.0);
      try {
        object->mesh = LoadMesh(file);
      } catch (const Error& e) {
        FailField(where, node, "file", e.what());
      }
      for (Eigen::Vector3d& v : object->mesh.vertices) v *= scale;
      return;
    }
    case ObjectShape::kPipe: {
      PipeShape s;
      s.outer_radius_m = length("outer_radius_m", s.outer_radius_m);
      s.wall_m = length("wall_m", s.wall_m);
      s.length_m = length("length_m", s.length_m);
      Checked(where, node, [&] { object->mesh = MakePipe(s, chord); });
      return;
    }
    case ObjectShape::kElbow: {
      ElbowShape s;
      s.outer_radius_m = length("outer_radius_m", s.outer_radius_m);
      s.wall_m = length("wall_m", s.wall_m);
      s.bend_radius_m = length("bend_radius_m", s.bend_radius_m);
      s.bend_angle_rad = Number(where, node, "bend_angle_rad", Range::kPositive, s.bend_angle_rad);
      Checked(where, node, [&] { object->mesh = MakeElbow(s, chord); });
      return;
    }
    case ObjectShape::kTee: {
      TeeShape s;
      s.outer_radius_m = length("outer_radius_m", s.outer_radius_m);
      s.wall_m = length("wall_m", s.wall_m);
      s.run_length_m = length("run_length_m", s.run_length_m);
      s.branch_length_m = length("branch_length_m", s.branch_length_m);
      Checked(where, node, [&] { object->mesh = MakeTee(s, chord); });
      return;
    }
    case ObjectShape::kFlange: {
      FlangeShape s;
      s.outer_radius_m = length("outer_radius_m", s.outer_radius_m);
      s.wall_m = length("wall_m", s.wall_m);
      s.length_m = length("length_m", s.length_m);
      s.flange_radius_m = length("flange_radius_m", s.flange_radius_m);
      s.flange_thickness_m = length("flange_thickness_m", s.flange_thickness_m);
      s.bolts = Integer(where, node, "bolts", 0, s.bolts);
      s.bolt_head_radius_m = length("bolt_head_radius_m", s.bolt_head_radius_m);
      s.bolt_head_height_m = length("bolt_head_height_m", s.bolt_head_height_m);
      Checked(where, node, [&] { object->mesh = MakeFlange(s, chord); });
      return;
    }
    case ObjectShape::kValve: {
      ValveShape s;
      s.outer_radius_m = length("outer_radius_m", s.outer_radius_m);
      s.wall_m = length("wall_m", s.wall_m);
      s.body_radius_m = length("body_radius_m", s.body_radius_m);
      s.body_length_m = length("body_length_m", s.body_length_m);
      s.stub_length_m = length("stub_length_m", s.stub_length_m);
      s.stem_radius_m = length("stem_radius_m", s.stem_radius_m);
      s.stem_length_m = length("stem_length_m", s.stem_length_m);
      s.handle_radius_m = length("handle_radius_m", s.handle_radius_m);
      if (Has(node, "handle")) {
        const std::string handle = String(where, node, "handle");
        if (handle == "wheel") {
          s.handle = ValveHandle::kWheel;
        } else if (handle == "lever") {
          s.handle = ValveHandle::kLever;
        } else {
          FailField(where, node, "handle", "got '" + handle + "', expected wheel or lever");
        }
      }
      Checked(where, node, [&] { object->mesh = MakeValve(s, chord); });
      return;
    }
    case ObjectShape::kGauge:
      object->gauge_length_m = Number(where, node, "length_m", Range::kPositive);
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
