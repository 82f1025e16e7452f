#include "scanner/sim/imr_objects.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::scanner::sim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kMaxSegments = 1 << 16;  // beyond this the chord error asked for is a mistake

std::string Num(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.9g", v);
  return buffer;
}

void RequirePositive(const char* shape, const char* field, double value) {
  if (!(std::isfinite(value) && value > 0.0)) {
    throw Error(std::string(shape) + ": " + field + ": " + Num(value) +
                ", expected a positive length in metres");
  }
}

// Triangle emission that keeps every shape's faces counter-clockwise seen from outside.
class Builder {
 public:
  explicit Builder(TriangleMesh* mesh) : mesh_(mesh) {}

  int Vertex(const Eigen::Vector3d& p) {
    mesh_->vertices.push_back(p);
    return static_cast<int>(mesh_->vertices.size()) - 1;
  }
  // Quad a-b-c-d counter-clockwise seen from outside, split along a-c. A triangle with a
  // repeated vertex (a fan at a pole, where a ring collapses to one vertex) is left out.
  void Quad(int a, int b, int c, int d) {
    Triangle(a, b, c);
    Triangle(a, c, d);
  }
  void Triangle(int a, int b, int c) {
    if (a == b || b == c || c == a) return;
    mesh_->triangles.emplace_back(a, b, c);
  }

 private:
  TriangleMesh* mesh_;
};

[[maybe_unused]] double ProfileArea(const std::vector<Eigen::Vector2d>& profile) {
  double twice = 0.0;
  for (size_t i = 0; i < profile.size(); ++i) {
    const Eigen::Vector2d& p = profile[i];
    const Eigen::Vector2d& q = profile[(i + 1) % profile.size()];
    twice += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * twice;
}

// Surface of revolution about z: the closed profile (r, z), counter-clockwise in the (r, z)
// half-plane with r >= 0, turned through a full circle in `segments` steps. Points on the axis
// (r = 0) become one vertex (a pole); a profile edge along the axis adds no surface. Along
// the profile ds and around the axis dphi, dphi x ds points out of a counter-clockwise
// profile, which fixes the quad order below.
void AddRevolution(TriangleMesh* mesh, const std::vector<Eigen::Vector2d>& profile, int segments,
                   const Eigen::Isometry3d& T = Eigen::Isometry3d::Identity()) {
  assert(profile.size() >= 3 && ProfileArea(profile) > 0.0);
  Builder b(mesh);
  std::vector<std::vector<int>> rings;
  rings.reserve(profile.size());
  for (const Eigen::Vector2d& p : profile) {
    assert(p.x() >= 0.0);
    if (p.x() == 0.0) {
      rings.emplace_back(segments, b.Vertex(T * Eigen::Vector3d(0.0, 0.0, p.y())));
      continue;
    }
    std::vector<int> ring(segments);
    for (int j = 0; j < segments; ++j) {
      const double phi = 2.0 * kPi * j / segments;
      ring[j] = b.Vertex(T * Eigen::Vector3d(p.x() * std::cos(phi), p.x() * std::sin(phi), p.y()));
    }
    rings.push_back(std::move(ring));
  }
  for (size_t i = 0; i < profile.size(); ++i) {
    const size_t next = (i + 1) % profile.size();
    if (profile[i].x() == 0.0 && profile[next].x() == 0.0) continue;
    for (int j = 0; j < segments; ++j) {
      const int jn = (j + 1) % segments;
      b.Quad(rings[i][j], rings[i][jn], rings[next][jn], rings[next][j]);
    }
  }
}

void Append(TriangleMesh* mesh, const TriangleMesh& part, const Eigen::Isometry3d& T) {
  const int base = static_cast<int>(mesh->vertices.size());
  for (const Eigen::Vector3d& v : part.vertices) mesh->vertices.push_back(T * v);
  for (const Eigen::Vector3i& t : part.triangles) {
    mesh->triangles.push_back(t + Eigen::Vector3i::Constant(base));
  }
}

// Prism (cylinder) with an exact number of sides: the hexagonal bolt heads use 6.
TriangleMesh Prism(double radius_m, double length_m, int sides) {
  TriangleMesh mesh;
  AddRevolution(&mesh,
                {{0.0, -0.5 * length_m},
                 {radius_m, -0.5 * length_m},
                 {radius_m, 0.5 * length_m},
                 {0.0, 0.5 * length_m}},
                sides);
  return mesh;
}

Eigen::Isometry3d Placed(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

// Rotations taking z_O to another axis (the pieces are all built along z).
Eigen::Matrix3d ZToX() { return Eigen::AngleAxisd(0.5 * kPi, Eigen::Vector3d::UnitY()).matrix(); }
Eigen::Matrix3d ZToY() { return Eigen::AngleAxisd(-0.5 * kPi, Eigen::Vector3d::UnitX()).matrix(); }

// The pipe section every shape but the primitives has.
void CheckPipeSection(const OptionChecks& check, double outer_radius_m, double wall_m) {
  check.Positive("outer_radius_m", outer_radius_m, "m");
  check.Positive("wall_m", wall_m, "m");
  check.Require(wall_m < outer_radius_m, "wall_m",
                "< outer_radius_m (" + Num(outer_radius_m) + " m)", wall_m);
}

}  // namespace

int CircleSegments(double radius_m, double chord_error_m) {
  RequirePositive("tessellation", "radius_m", radius_m);
  RequirePositive("tessellation", "chord_error_m", chord_error_m);
  double n = 8.0;
  if (chord_error_m < radius_m) {
    // Sagitta of n segments: r (1 - cos(pi / n)) <= e  <=>  n >= pi / acos(1 - e / r).
    n = std::max(n, std::ceil(kPi / std::acos(1.0 - chord_error_m / radius_m)));
  }
  if (n > kMaxSegments) {
    throw Error("tessellation: chord_error_m " + Num(chord_error_m) + " on radius " +
                Num(radius_m) + " m needs more than " + std::to_string(kMaxSegments) +
                " segments per circle");
  }
  const int segments = static_cast<int>(n);
  return (segments + 3) / 4 * 4;
}

TriangleMesh MakeRectangle(double size_x_m, double size_y_m) {
  RequirePositive("plane", "size_m[0]", size_x_m);
  RequirePositive("plane", "size_m[1]", size_y_m);
  const double x = 0.5 * size_x_m, y = 0.5 * size_y_m;
  TriangleMesh mesh;
  mesh.vertices = {{-x, -y, 0.0}, {x, -y, 0.0}, {x, y, 0.0}, {-x, y, 0.0}};
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  return mesh;
}

TriangleMesh MakeBox(const Eigen::Vector3d& size_m) {
  for (int i = 0; i < 3; ++i) {
    RequirePositive("box", ("size_m[" + std::to_string(i) + "]").c_str(), size_m[i]);
  }
  TriangleMesh mesh;
  // Corner i has coordinate bits (x, y, z) = (i & 1, i & 2, i & 4).
  for (int i = 0; i < 8; ++i) {
    mesh.vertices.emplace_back((i & 1 ? 0.5 : -0.5) * size_m.x(), (i & 2 ? 0.5 : -0.5) * size_m.y(),
                               (i & 4 ? 0.5 : -0.5) * size_m.z());
  }
  Builder b(&mesh);
  b.Quad(0, 4, 6, 2);  // -x
  b.Quad(1, 3, 7, 5);  // +x
  b.Quad(0, 1, 5, 4);  // -y
  b.Quad(2, 6, 7, 3);  // +y
  b.Quad(0, 2, 3, 1);  // -z
  b.Quad(4, 5, 7, 6);  // +z
  return mesh;
}

TriangleMesh MakeCylinder(double radius_m, double length_m, double chord_error_m) {
  RequirePositive("cylinder", "radius_m", radius_m);
  RequirePositive("cylinder", "length_m", length_m);
  return Prism(radius_m, length_m, CircleSegments(radius_m, chord_error_m));
}

TriangleMesh MakeUvSphere(double radius_m, double chord_error_m) {
  RequirePositive("sphere", "radius_m", radius_m);
  const int segments = CircleSegments(radius_m, chord_error_m);
  const int latitudes = segments / 2;
  std::vector<Eigen::Vector2d> profile;
  for (int k = 0; k <= latitudes; ++k) {
    const double theta = kPi * k / latitudes;
    // Exact zeros at the poles, so that they become single vertices.
    const double r = (k == 0 || k == latitudes) ? 0.0 : radius_m * std::sin(theta);
    profile.emplace_back(r, -radius_m * std::cos(theta));
  }
  TriangleMesh mesh;
  AddRevolution(&mesh, profile, segments);
  return mesh;
}

void PipeShape::Check() const {
  const OptionChecks check("PipeShape");
  CheckPipeSection(check, outer_radius_m, wall_m);
  check.Positive("length_m", length_m, "m");
  check.NonNegative("dent_radius_m", dent_radius_m, "m");
  if (dent_radius_m == 0.0) return;
  check.Require(dent_radius_m < kPi * outer_radius_m, "dent_radius_m",
                "< pi x outer_radius_m (" + Num(kPi * outer_radius_m) + " m)", dent_radius_m);
  check.NonNegative("dent_depth_m", dent_depth_m, "m");
  check.Require(dent_depth_m < wall_m, "dent_depth_m", "< wall_m (" + Num(wall_m) + " m)",
                dent_depth_m);
  check.Finite("dent_angle_rad", dent_angle_rad);
  check.Require(std::abs(dent_position_m) + dent_radius_m < 0.5 * length_m, "dent_position_m",
                "the dent within the pipe (|position| + radius < " + Num(0.5 * length_m) + " m)",
                dent_position_m);
}

namespace {

// How deep the dent is at a point of the outer wall (its angle about z_O and its z).
double DentDepth(const PipeShape& shape, double angle_rad, double z_m) {
  const double turn = std::remainder(angle_rad - shape.dent_angle_rad, 2.0 * kPi);
  const double s = std::hypot(shape.outer_radius_m * turn, z_m - shape.dent_position_m);
  if (s >= shape.dent_radius_m) return 0.0;
  return shape.dent_depth_m * 0.5 * (1.0 + std::cos(kPi * s / shape.dent_radius_m));
}

// The outer wall of a dented pipe: rings and segments at most an eighth of the dent's radius
// apart (the whole wall, so that an undented epoch has the same vertices), then the wall's
// vertices pressed in.
TriangleMesh MakeDentedPipe(const PipeShape& shape, double chord_error_m) {
  const double ro = shape.outer_radius_m, ri = ro - shape.wall_m, h = 0.5 * shape.length_m;
  const double step = shape.dent_radius_m / 8.0;
  const int rings = static_cast<int>(std::ceil(shape.length_m / step));
  std::vector<Eigen::Vector2d> profile = {{ri, -h}};
  for (int k = 0; k <= rings; ++k) profile.emplace_back(ro, -h + shape.length_m * k / rings);
  profile.emplace_back(ri, h);
  const int around = std::max(CircleSegments(ro, chord_error_m),
                              static_cast<int>(std::ceil(2.0 * kPi * ro / step / 4.0)) * 4);
  TriangleMesh mesh;
  AddRevolution(&mesh, profile, around);
  for (Eigen::Vector3d& v : mesh.vertices) {
    const double r = v.head<2>().norm();
    if (std::abs(r - ro) > 1e-12 * ro) continue;  // the inner wall
    const double depth = DentDepth(shape, std::atan2(v.y(), v.x()), v.z());
    v.head<2>() *= (ro - depth) / r;
  }
  return mesh;
}

}  // namespace

TriangleMesh MakePipe(const PipeShape& shape, double chord_error_m) {
  shape.Check();
  if (shape.dent_radius_m > 0.0) return MakeDentedPipe(shape, chord_error_m);
  const double ro = shape.outer_radius_m, ri = ro - shape.wall_m, h = 0.5 * shape.length_m;
  TriangleMesh mesh;
  AddRevolution(&mesh, {{ri, -h}, {ro, -h}, {ro, h}, {ri, h}}, CircleSegments(ro, chord_error_m));
  return mesh;
}

void ElbowShape::Check() const {
  const OptionChecks check("ElbowShape");
  CheckPipeSection(check, outer_radius_m, wall_m);
  check.Positive("bend_radius_m", bend_radius_m, "m");
  check.Require(bend_radius_m > outer_radius_m, "bend_radius_m",
                "> outer_radius_m (" + Num(outer_radius_m) +
                    " m) so that the inside of the bend does not fold over",
                bend_radius_m);
  check.Require(bend_angle_rad > 0.0 && bend_angle_rad < 2.0 * kPi, "bend_angle_rad",
                "in (0, 2 pi) rad", bend_angle_rad);
}

TriangleMesh MakeElbow(const ElbowShape& shape, double chord_error_m) {
  shape.Check();
  const double R = shape.bend_radius_m, ro = shape.outer_radius_m, ri = ro - shape.wall_m;
  const int around = CircleSegments(ro, chord_error_m);
  // Along the bend the outermost fibre (radius R + ro) sets the chord error.
  const int along =
      std::max(1, static_cast<int>(std::ceil(shape.bend_angle_rad *
                                             CircleSegments(R + ro, chord_error_m) / (2.0 * kPi))));
  TriangleMesh mesh;
  Builder b(&mesh);
  // Section at bend angle phi: centre + (R + rho cos beta) e_r(phi) + rho sin beta y, with the
  // bend centre (R, 0, 0) and e_r(phi) = (-cos phi, 0, sin phi) pointing at the centre line.
  auto ring = [&](int k, double rho) {
    const double phi = shape.bend_angle_rad * k / along;
    const Eigen::Vector3d e_r(-std::cos(phi), 0.0, std::sin(phi));
    std::vector<int> indices(around);
    for (int j = 0; j < around; ++j) {
      const double beta = 2.0 * kPi * j / around;
      indices[j] = b.Vertex(Eigen::Vector3d(R, 0.0, 0.0) + (R + rho * std::cos(beta)) * e_r +
                            rho * std::sin(beta) * Eigen::Vector3d::UnitY());
    }
    return indices;
  };
  std::vector<std::vector<int>> outer, inner;
  for (int k = 0; k <= along; ++k) {
    outer.push_back(ring(k, ro));
    inner.push_back(ring(k, ri));
  }
  // d(phi) x d(beta) is the outward normal of the section circle: quads (k, j), (k + 1, j),
  // (k + 1, j + 1), (k, j + 1) face out of the outer surface; the bore faces the other way.
  for (int k = 0; k < along; ++k) {
    for (int j = 0; j < around; ++j) {
      const int jn = (j + 1) % around;
      b.Quad(outer[k][j], outer[k + 1][j], outer[k + 1][jn], outer[k][jn]);
      b.Quad(inner[k][j], inner[k][jn], inner[k + 1][jn], inner[k + 1][j]);
    }
  }
  // Annular ends: the start faces back along the centre line, the end forward.
  for (int j = 0; j < around; ++j) {
    const int jn = (j + 1) % around;
    b.Quad(outer[0][j], outer[0][jn], inner[0][jn], inner[0][j]);
    b.Quad(outer[along][j], inner[along][j], inner[along][jn], outer[along][jn]);
  }
  return mesh;
}

void TeeShape::Check() const {
  const OptionChecks check("TeeShape");
  CheckPipeSection(check, outer_radius_m, wall_m);
  check.Positive("run_length_m", run_length_m, "m");
  check.Require(run_length_m > 2.0 * outer_radius_m, "run_length_m",
                "> the branch's diameter (" + Num(2.0 * outer_radius_m) + " m)", run_length_m);
  check.Require(std::isfinite(branch_length_m) && branch_length_m > outer_radius_m,
                "branch_length_m", "> outer_radius_m (" + Num(outer_radius_m) + " m)",
                branch_length_m);
}

TriangleMesh MakeTee(const TeeShape& shape, double chord_error_m) {
  shape.Check();
  TriangleMesh mesh =
      MakePipe({shape.outer_radius_m, shape.wall_m, shape.run_length_m}, chord_error_m);
  const TriangleMesh branch =
      MakePipe({shape.outer_radius_m, shape.wall_m, shape.branch_length_m}, chord_error_m);
  Append(&mesh, branch, Placed(ZToX(), Eigen::Vector3d(0.5 * shape.branch_length_m, 0.0, 0.0)));
  return mesh;
}

void FlangeShape::Check() const {
  const OptionChecks check("FlangeShape");
  CheckPipeSection(check, outer_radius_m, wall_m);
  check.Positive("length_m", length_m, "m");
  check.Positive("flange_thickness_m", flange_thickness_m, "m");
  check.Require(flange_thickness_m < length_m, "flange_thickness_m",
                "< length_m (" + Num(length_m) + " m)", flange_thickness_m);
  check.Require(std::isfinite(flange_radius_m) && flange_radius_m > outer_radius_m,
                "flange_radius_m", "> outer_radius_m (" + Num(outer_radius_m) + " m)",
                flange_radius_m);
  check.AtLeast("bolts", bolts, 0);
  if (bolts == 0) return;
  check.Positive("bolt_head_radius_m", bolt_head_radius_m, "m");
  check.Positive("bolt_head_height_m", bolt_head_height_m, "m");
  const double circle = 0.5 * (outer_radius_m + flange_radius_m);
  const double half_width = 0.5 * (flange_radius_m - outer_radius_m);
  check.Require(bolt_head_radius_m < half_width, "bolt_head_radius_m",
                "< half the flange's width beyond the pipe (" + Num(half_width) + " m)",
                bolt_head_radius_m);
  check.Require(bolts == 1 || circle * std::sin(kPi / bolts) > bolt_head_radius_m, "bolts",
                "heads of radius " + Num(bolt_head_radius_m) +
                    " m that do not overlap on a bolt circle of radius " + Num(circle) + " m",
                bolts);
  for (std::size_t i = 0; i < missing_bolts.size(); ++i) {
    const int k = missing_bolts[i];
    check.Require(k >= 0 && k < bolts, "missing_bolts[" + std::to_string(i) + "]",
                  "a bolt's index in [0, " + std::to_string(bolts) + ")", k);
    check.Require(std::count(missing_bolts.begin(), missing_bolts.end(), k) == 1,
                  "missing_bolts[" + std::to_string(i) + "]", "each bolt once", k);
  }
}

TriangleMesh MakeFlange(const FlangeShape& shape, double chord_error_m) {
  shape.Check();
  const double ro = shape.outer_radius_m, ri = ro - shape.wall_m, h = 0.5 * shape.length_m;
  const double rf = shape.flange_radius_m, back = h - shape.flange_thickness_m;
  TriangleMesh mesh;
  AddRevolution(&mesh, {{ri, -h}, {ro, -h}, {ro, back}, {rf, back}, {rf, h}, {ri, h}},
                CircleSegments(rf, chord_error_m));
  const double sink = 0.001;  // the heads reach into the flange: no coplanar faces
  const double length = shape.bolt_head_height_m + sink;
  const TriangleMesh head = Prism(shape.bolt_head_radius_m, length, 6);
  const double circle = 0.5 * (ro + rf);
  for (int k = 0; k < shape.bolts; ++k) {
    if (std::count(shape.missing_bolts.begin(), shape.missing_bolts.end(), k) > 0) continue;
    const double angle = 2.0 * kPi * (k + 0.5) / shape.bolts;
    Append(&mesh, head,
           Placed(Eigen::Matrix3d::Identity(),
                  Eigen::Vector3d(circle * std::cos(angle), circle * std::sin(angle),
                                  back + sink - 0.5 * length)));
  }
  return mesh;
}

void ValveShape::Check() const {
  const OptionChecks check("ValveShape");
  CheckPipeSection(check, outer_radius_m, wall_m);
  check.Positive("body_length_m", body_length_m, "m");
  check.Positive("stub_length_m", stub_length_m, "m");
  check.Positive("stem_radius_m", stem_radius_m, "m");
  check.Require(std::isfinite(body_radius_m) && body_radius_m > outer_radius_m / 0.8,
                "body_radius_m",
                "> 1.25 x outer_radius_m (" + Num(1.25 * outer_radius_m) +
                    " m: the body's chamfered ends must cover the pipe)",
                body_radius_m);
  check.Require(stem_radius_m < 0.5 * body_radius_m, "stem_radius_m",
                "< half body_radius_m (" + Num(0.5 * body_radius_m) + " m)", stem_radius_m);
  check.Require(std::isfinite(stem_length_m) && stem_length_m > body_radius_m + 0.02,
                "stem_length_m", "> body_radius_m + 20 mm (" + Num(body_radius_m + 0.02) + " m)",
                stem_length_m);
  check.Require(std::isfinite(handle_radius_m) && handle_radius_m > 3.0 * stem_radius_m,
                "handle_radius_m", "> 3 x stem_radius_m (" + Num(3.0 * stem_radius_m) + " m)",
                handle_radius_m);
  check.Require(handle == ValveHandle::kWheel || handle == ValveHandle::kLever, "handle",
                "wheel or lever", static_cast<int>(handle));
}

TriangleMesh MakeValve(const ValveShape& shape, double chord_error_m) {
  shape.Check();
  TriangleMesh mesh;
  // Body: a barrel, chamfered at both ends to 0.8 of its radius.
  const double rb = shape.body_radius_m, hb = 0.5 * shape.body_length_m;
  const double chamfer = std::min(0.2 * rb, 0.5 * hb);
  AddRevolution(&mesh,
                {{0.0, -hb},
                 {0.8 * rb, -hb},
                 {rb, -hb + chamfer},
                 {rb, hb - chamfer},
                 {0.8 * rb, hb},
                 {0.0, hb}},
                CircleSegments(rb, chord_error_m));
  // Stubs start half-way into the body, so their inner ends are hidden in it.
  const double stub_length = shape.stub_length_m + 0.5 * hb;
  const TriangleMesh stub =
      MakePipe({shape.outer_radius_m, shape.wall_m, stub_length}, chord_error_m);
  for (const double side : {-1.0, 1.0}) {
    Append(&mesh, stub,
           Placed(Eigen::Matrix3d::Identity(),
                  Eigen::Vector3d(0.0, 0.0, side * (0.5 * hb + 0.5 * stub_length))));
  }
  // Stem from the pipe axis (inside the body) up along +y_O.
  const double top = shape.stem_length_m;
  Append(&mesh, MakeCylinder(shape.stem_radius_m, top, chord_error_m),
         Placed(ZToY(), Eigen::Vector3d(0.0, 0.5 * top, 0.0)));
  if (shape.handle == ValveHandle::kLever) {
    // A one-sided bar along +z_O, its top 2 mm above the stem's end (no coplanar faces).
    const double reach = shape.handle_radius_m;
    Append(&mesh, MakeBox(Eigen::Vector3d(3.0 * shape.stem_radius_m, 0.012, 1.2 * reach)),
           Placed(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.0, top - 0.004, 0.4 * reach)));
    return mesh;
  }
  // Hand wheel: a torus rim around the stem's top, a hub and two crossed spokes.
  const double rim = std::max(0.004, 0.1 * shape.handle_radius_m);  // tube radius of the rim
  const double wheel_y = top - rim;
  const int rim_around = CircleSegments(rim, chord_error_m);
  std::vector<Eigen::Vector2d> section;
  for (int j = 0; j < rim_around; ++j) {
    const double beta = 2.0 * kPi * j / rim_around;
    section.emplace_back(shape.handle_radius_m + rim * std::cos(beta), rim * std::sin(beta));
  }
  AddRevolution(&mesh, section, CircleSegments(shape.handle_radius_m + rim, chord_error_m),
                Placed(ZToY(), Eigen::Vector3d(0.0, wheel_y, 0.0)));
  Append(&mesh, MakeCylinder(2.0 * shape.stem_radius_m, 3.0 * rim, chord_error_m),
         Placed(ZToY(), Eigen::Vector3d(0.0, wheel_y + 0.5 * rim, 0.0)));
  const TriangleMesh spoke = MakeCylinder(0.6 * rim, 2.0 * shape.handle_radius_m, chord_error_m);
  Append(&mesh, spoke, Placed(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.0, wheel_y, 0.0)));
  Append(&mesh, spoke, Placed(ZToX(), Eigen::Vector3d(0.0, wheel_y, 0.0)));
  return mesh;
}

void PanelShape::Check() const {
  const OptionChecks check("PanelShape");
  check.Positive("width_m", width_m, "m");
  check.Positive("height_m", height_m, "m");
  check.Positive("thickness_m", thickness_m, "m");
  check.Positive("bar_m", bar_m, "m");
  check.Require(std::isfinite(handle_offset_m) && handle_offset_m >= 0.0 &&
                    handle_offset_m < 0.5 * (width_m - bar_m),
                "handle_offset_m", "in [0, (width_m - bar_m) / 2)", handle_offset_m);
  check.Require(
      std::isfinite(handle_span_m) && handle_span_m > bar_m && handle_span_m + bar_m < height_m,
      "handle_span_m", "in (bar_m, height_m - bar_m)", handle_span_m);
  check.Require(std::isfinite(handle_depth_m) && handle_depth_m > bar_m, "handle_depth_m",
                "> bar_m (" + Num(bar_m) + " m)", handle_depth_m);
}

TriangleMesh MakePanel(const PanelShape& shape) {
  shape.Check();
  TriangleMesh mesh = MakeBox(Eigen::Vector3d(shape.width_m, shape.height_m, shape.thickness_m));
  for (Eigen::Vector3d& v : mesh.vertices) v.z() -= 0.5 * shape.thickness_m;
  // Each post, a little thinner than the bar, runs 1 mm into the plate and up into the bar, so
  // that no faces coincide.
  const double post_length = shape.handle_depth_m - 0.5 * shape.bar_m + 0.001;
  const double post_width = 0.9 * shape.bar_m;
  const TriangleMesh post = MakeBox(Eigen::Vector3d(post_width, post_width, post_length));
  const TriangleMesh bar =
      MakeBox(Eigen::Vector3d(shape.bar_m, shape.handle_span_m + shape.bar_m, shape.bar_m));
  for (const double x : {-shape.handle_offset_m, shape.handle_offset_m}) {
    for (const double y : {-0.5 * shape.handle_span_m, 0.5 * shape.handle_span_m}) {
      Append(&mesh, post,
             Placed(Eigen::Matrix3d::Identity(), Eigen::Vector3d(x, y, 0.5 * post_length - 0.001)));
    }
    Append(&mesh, bar,
           Placed(Eigen::Matrix3d::Identity(),
                  Eigen::Vector3d(x, 0.0, shape.handle_depth_m - 0.5 * shape.bar_m)));
  }
  return mesh;
}

TriangleMesh MakeGaugeBlock(double length_m) {
  RequirePositive("gauge", "length_m", length_m);
  return MakeBox(Eigen::Vector3d(kGaugeWidthM, length_m, kGaugeThicknessM));
}

}  // namespace uwscan::scanner::sim
