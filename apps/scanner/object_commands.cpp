#include "apps/scanner/object_commands.hpp"

#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "apps/cli/number_validators.hpp"
#include "apps/cli/output_path.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "perception/cloud/point_cloud.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/triangle_mesh.hpp"
#include "scanner/sim/imr_objects.hpp"

namespace uwscan::app {
namespace {

namespace sim = scanner::sim;

struct MakeObjectArgs {
  std::string shape;
  std::string output;
  double length_m = 0.0;
  double radius_m = 0.0;
  double wall_m = 0.0;
  std::vector<double> size_m;
  double bend_radius_m = 0.0;
  double bend_angle_rad = 0.0;
  double branch_length_m = 0.0;
  double flange_radius_m = 0.0;
  double flange_thickness_m = 0.0;
  int bolts = 0;
  std::string handle;
  double handle_radius_m = 0.0;
  double body_radius_m = 0.0;
  double stem_length_m = 0.0;
  double chord_error_m = sim::kDefaultChordErrorM;
  int points = 0;  // > 0: a cloud of this many surface points instead of the mesh
  double noise_m = 0.0003;
  std::uint64_t seed = 1;
};

// The dimension options each shape reads; any other one given is a mistake worth stopping on
// (a --bend-radius-m on a pipe would otherwise be silently ignored).
const std::map<std::string, std::set<std::string>>& ShapeOptions() {
  static const std::map<std::string, std::set<std::string>> options = {
      {"plane", {"--size-m"}},
      {"box", {"--size-m"}},
      {"sphere", {"--radius-m", "--chord-error-m"}},
      {"cylinder", {"--radius-m", "--length-m", "--chord-error-m"}},
      {"pipe", {"--radius-m", "--wall-m", "--length-m", "--chord-error-m"}},
      {"elbow",
       {"--radius-m", "--wall-m", "--bend-radius-m", "--bend-angle-rad", "--chord-error-m"}},
      {"tee", {"--radius-m", "--wall-m", "--length-m", "--branch-length-m", "--chord-error-m"}},
      {"flange",
       {"--radius-m", "--wall-m", "--length-m", "--flange-radius-m", "--flange-thickness-m",
        "--bolts", "--chord-error-m"}},
      {"valve",
       {"--radius-m", "--wall-m", "--body-radius-m", "--stem-length-m", "--handle",
        "--handle-radius-m", "--chord-error-m"}},
      {"gauge", {"--length-m"}},
      {"panel", {"--size-m"}},
  };
  return options;
}

const std::vector<std::string> kDimensionOptions = {
    "--length-m",           "--radius-m",       "--wall-m",          "--size-m",
    "--bend-radius-m",      "--bend-angle-rad", "--branch-length-m", "--flange-radius-m",
    "--flange-thickness-m", "--bolts",          "--handle",          "--handle-radius-m",
    "--body-radius-m",      "--stem-length-m",  "--chord-error-m"};

// The solids without a bore: plane, box, sphere, cylinder, gauge block, panel; nullopt for
// another shape.
std::optional<scanner::TriangleMesh> MakeSolidMesh(const MakeObjectArgs& a, const CLI::App& cmd) {
  auto given = [&](const char* option) { return cmd.count(option) > 0; };
  const double chord = a.chord_error_m;
  if (a.shape == "plane" || a.shape == "box") {
    const size_t n = a.shape == "plane" ? 2 : 3;
    std::vector<double> size =
        given("--size-m") ? a.size_m : std::vector<double>(n, a.shape == "plane" ? 1.0 : 0.1);
    if (size.size() != n) {
      throw Error("--size-m: a " + a.shape + " takes " + std::to_string(n) + " lengths");
    }
    return a.shape == "plane" ? sim::MakeRectangle(size[0], size[1])
                              : sim::MakeBox(Eigen::Vector3d(size[0], size[1], size[2]));
  }
  if (a.shape == "sphere") return sim::MakeUvSphere(given("--radius-m") ? a.radius_m : 0.1, chord);
  if (a.shape == "cylinder") {
    return sim::MakeCylinder(given("--radius-m") ? a.radius_m : 0.05,
                             given("--length-m") ? a.length_m : 0.2, chord);
  }
  if (a.shape == "gauge") return sim::MakeGaugeBlock(given("--length-m") ? a.length_m : 0.05);
  if (a.shape == "panel") {
    sim::PanelShape s;
    if (given("--size-m")) {
      if (a.size_m.size() != 3)
        throw Error("--size-m: a panel takes 3 lengths: width height thickness");
      s.width_m = a.size_m[0];
      s.height_m = a.size_m[1];
      s.thickness_m = a.size_m[2];
    }
    return sim::MakePanel(s);
  }
  return std::nullopt;
}

// The pipe-like shapes: pipe, elbow, tee, flange, valve. Unset options keep the shape's defaults.
scanner::TriangleMesh MakePipeLikeMesh(const MakeObjectArgs& a, const CLI::App& cmd) {
  auto given = [&](const char* option) { return cmd.count(option) > 0; };
  const double chord = a.chord_error_m;
  auto set = [&](const char* option, double value, double* field) {
    if (given(option)) *field = value;
  };
  if (a.shape == "pipe") {
    sim::PipeShape s;
    set("--radius-m", a.radius_m, &s.outer_radius_m);
    set("--wall-m", a.wall_m, &s.wall_m);
    set("--length-m", a.length_m, &s.length_m);
    return sim::MakePipe(s, chord);
  }
  if (a.shape == "elbow") {
    sim::ElbowShape s;
    set("--radius-m", a.radius_m, &s.outer_radius_m);
    set("--wall-m", a.wall_m, &s.wall_m);
    set("--bend-radius-m", a.bend_radius_m, &s.bend_radius_m);
    set("--bend-angle-rad", a.bend_angle_rad, &s.bend_angle_rad);
    return sim::MakeElbow(s, chord);
  }
  if (a.shape == "tee") {
    sim::TeeShape s;
    set("--radius-m", a.radius_m, &s.outer_radius_m);
    set("--wall-m", a.wall_m, &s.wall_m);
    set("--length-m", a.length_m, &s.run_length_m);
    set("--branch-length-m", a.branch_length_m, &s.branch_length_m);
    return sim::MakeTee(s, chord);
  }
  if (a.shape == "flange") {
    sim::FlangeShape s;
    set("--radius-m", a.radius_m, &s.outer_radius_m);
    set("--wall-m", a.wall_m, &s.wall_m);
    set("--length-m", a.length_m, &s.length_m);
    set("--flange-radius-m", a.flange_radius_m, &s.flange_radius_m);
    set("--flange-thickness-m", a.flange_thickness_m, &s.flange_thickness_m);
    if (given("--bolts")) s.bolts = a.bolts;
    return sim::MakeFlange(s, chord);
  }
  sim::ValveShape s;  // the only shape left (CLI::IsMember checked the name)
  set("--radius-m", a.radius_m, &s.outer_radius_m);
  set("--wall-m", a.wall_m, &s.wall_m);
  set("--body-radius-m", a.body_radius_m, &s.body_radius_m);
  set("--stem-length-m", a.stem_length_m, &s.stem_length_m);
  set("--handle-radius-m", a.handle_radius_m, &s.handle_radius_m);
  if (given("--handle"))
    s.handle = a.handle == "lever" ? sim::ValveHandle::kLever : sim::ValveHandle::kWheel;
  return sim::MakeValve(s, chord);
}

scanner::TriangleMesh MakeMesh(const MakeObjectArgs& a, const CLI::App& cmd) {
  const std::set<std::string>& allowed = ShapeOptions().at(a.shape);
  for (const std::string& option : kDimensionOptions) {
    if (cmd.count(option) > 0 && allowed.count(option) == 0) {
      throw Error(option + ": does not apply to a " + a.shape);
    }
  }
  if (std::optional<scanner::TriangleMesh> solid = MakeSolidMesh(a, cmd)) return *std::move(solid);
  return MakePipeLikeMesh(a, cmd);
}

void RunMakeObject(const MakeObjectArgs& a, const CLI::App& cmd) {
  const scanner::TriangleMesh mesh = MakeMesh(a, cmd);
  if (a.points > 0) {
    CheckCloudOutputPath(a.output, "-o", {});
    perception::WriteCloud(a.output, perception::MakeCloud(scanner::ScannedSurface(
                                         mesh, a.points, a.noise_m, a.seed)));
    std::printf("wrote %s: %d points over a %s's surface, %g m noise\n", a.output.c_str(), a.points,
                a.shape.c_str(), a.noise_m);
    return;
  }
  scanner::WriteMeshPly(mesh, a.output);
  Eigen::Vector3d lo = mesh.vertices.front(), hi = mesh.vertices.front();
  for (const Eigen::Vector3d& v : mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const Eigen::Vector3d extent = hi - lo;
  std::printf("wrote %s: %s, %zu vertices, %zu triangles, %.4f x %.4f x %.4f m\n", a.output.c_str(),
              a.shape.c_str(), mesh.vertices.size(), mesh.triangles.size(), extent.x(), extent.y(),
              extent.z());
}

}  // namespace

void AddMakeObjectCommand(CLI::App& app) {
  auto a = std::make_shared<MakeObjectArgs>();
  CLI::App* cmd = app.add_subcommand(
      "make-object",
      "write a procedurally generated IMR object as a PLY mesh in its own frame (metres); "
      "unset dimensions take the shape's defaults");
  std::vector<std::string> shapes;
  for (const auto& [name, options] : ShapeOptions()) shapes.push_back(name);
  cmd->add_option("shape", a->shape,
                  "plane, box, sphere, cylinder, pipe, elbow, tee, flange, valve, gauge, panel")
      ->required()
      ->check(CLI::IsMember(shapes));
  cmd->add_option("-o,--output", a->output, "PLY file to write (.ply or .pcd with --points)")
      ->required();
  cmd->add_option("--points", a->points,
                  "write this many points over the surface instead of the mesh, as a scanner "
                  "that saw all of the object would (a stand-in for a scan of it: build-db "
                  "takes it)")
      ->check(CLI::Range(20, 10000000));
  cmd->add_option("--noise-m", a->noise_m, "--points: Gaussian noise on each coordinate, metres")
      ->capture_default_str()
      ->check(kNonNegativeNumber);
  cmd->add_option("--seed", a->seed, "--points: sampling and noise seed")->capture_default_str();
  cmd->add_option("--length-m", a->length_m,
                  "cylinder, pipe or flange length along z; tee run length; gauge length along y")
      ->check(kObjectLengthMetres);
  cmd->add_option("--radius-m", a->radius_m, "sphere or cylinder radius; pipe outer radius")
      ->check(kObjectLengthMetres);
  cmd->add_option("--wall-m", a->wall_m, "pipe wall thickness")->check(kObjectLengthMetres);
  cmd->add_option("--size-m", a->size_m, "plane: X Y; box: X Y Z; panel: width height thickness")
      ->expected(2, 3)
      ->check(kObjectLengthMetres);
  cmd->add_option("--bend-radius-m", a->bend_radius_m, "elbow: radius of the centre line's bend")
      ->check(kObjectLengthMetres);
  cmd->add_option("--bend-angle-rad", a->bend_angle_rad, "elbow: bend angle");
  cmd->add_option("--branch-length-m", a->branch_length_m, "tee: branch length from the run's axis")
      ->check(kObjectLengthMetres);
  cmd->add_option("--flange-radius-m", a->flange_radius_m, "flange: outer radius of the disc")
      ->check(kObjectLengthMetres);
  cmd->add_option("--flange-thickness-m", a->flange_thickness_m, "flange: thickness of the disc")
      ->check(kObjectLengthMetres);
  cmd->add_option("--bolts", a->bolts, "flange: number of bolt heads")->check(kNonNegativeNumber);
  cmd->add_option("--handle", a->handle, "valve: wheel or lever")
      ->check(CLI::IsMember({"wheel", "lever"}));
  cmd->add_option("--handle-radius-m", a->handle_radius_m, "valve: wheel radius or lever reach")
      ->check(kObjectLengthMetres);
  cmd->add_option("--body-radius-m", a->body_radius_m, "valve: body radius")
      ->check(kObjectLengthMetres);
  cmd->add_option("--stem-length-m", a->stem_length_m, "valve: stem top above the pipe axis")
      ->check(kObjectLengthMetres);
  cmd->add_option("--chord-error-m", a->chord_error_m,
                  "largest distance of a chord from the true curved surface (default 1e-4)");
  cmd->callback([a, cmd] { RunMakeObject(*a, *cmd); });
}

}  // namespace uwscan::app
