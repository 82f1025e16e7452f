#include "apps/viewer/view_command.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apps/cli/data_cache.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/output_path.hpp"
#include "scanner/common/error.hpp"
#include "scanner/sim/ray_caster.hpp"
#include "scanner/sim/scene.hpp"
#include "viewer/render/display.hpp"
#include "viewer/render/dive_log_follower.hpp"
#include "viewer/render/interactive_view.hpp"
#include "viewer/render/live_view.hpp"
#include "viewer/render/screenshot.hpp"
#include "viewer/scene/scene_files.hpp"
#include "viewer/scene/surface_error.hpp"

namespace uwscan::app {
namespace {

struct ViewArgs {
  std::vector<std::string> files;
  std::string colour;  // empty: by object when a recognition report is shown, else by height
  std::vector<double> range;
  double point_size_px = 2.0;
  bool edl = false;
  std::string camera = "fit";
  std::string size = "1280x960";
  std::size_t max_points = 2'000'000;
  std::vector<double> up;
  std::string method;
  std::string screenshot;
  bool no_colour_bar = false;
  int ellipsoid_every = 10;
  bool follow = false;
  std::int64_t frames = 0;
  double timeout_s = 0.0;
  double decay_s = 0.0;
  std::string scene;  // a simulated scene: clouds coloured by their distance to its surfaces
};

// How far from the scene's surfaces a point still gets a distance (beyond: no value).
constexpr double kSurfaceSearch_m = 0.5;

// "WxH" -> width, height in pixels.
std::pair<int, int> ParseSize(const std::string& text) {
  const std::size_t x = text.find('x');
  try {
    if (x != std::string::npos) {
      std::size_t a = 0, b = 0;
      const int w = std::stoi(text.substr(0, x), &a);
      const int h = std::stoi(text.substr(x + 1), &b);
      if (a == x && b == text.size() - x - 1) return {w, h};
    }
  } catch (const std::exception&) {
  }
  throw Error("--size " + text + ": expected WIDTHxHEIGHT in pixels, e.g. 1280x960");
}

bool Shows(const ViewArgs& a, viewer::FileKind kind) {
  for (const std::string& file : a.files) {
    if (std::filesystem::path(file).extension() == ".json" &&
        std::filesystem::is_regular_file(file) && viewer::KindOfFile(file) == kind) {
      return true;
    }
  }
  return false;
}

viewer::RenderOptions RenderOptionsFrom(const ViewArgs& a) {
  viewer::RenderOptions o;
  // A recognition report's scan is in the sensor's frame (y down): by default it is coloured by
  // object (a segment and its model share a colour) and shown upright as the sensor saw it.
  // A change report's points by their significant deviation.
  const bool recognition = Shows(a, viewer::FileKind::kRecognitionReport);
  const std::string colour_name = !a.colour.empty()                           ? a.colour
                                  : recognition                               ? "object"
                                  : Shows(a, viewer::FileKind::kChangeReport) ? "deviation"
                                  : !a.scene.empty()                          ? "error"
                                                                              : "height";
  const std::optional<viewer::ColourMode> colour = viewer::ParseColourMode(colour_name);
  if (!colour)
    throw Error("--colour " + colour_name + ": use height, error, intensity, object or deviation");
  o.colour = *colour;
  const std::optional<viewer::CameraPreset> camera = viewer::ParseCameraPreset(a.camera);
  if (!camera) throw Error("--camera " + a.camera + ": use fit, top or side");
  o.camera = *camera;
  if (!a.range.empty()) o.range = viewer::ScalarRange{a.range[0], a.range[1]};
  o.point_size_px = a.point_size_px;
  o.eye_dome_lighting = a.edl;
  std::tie(o.width_px, o.height_px) = ParseSize(a.size);
  o.max_points = a.max_points;
  if (!a.up.empty()) {
    o.up = Eigen::Vector3d(a.up[0], a.up[1], a.up[2]);
  } else if (recognition) {
    o.up = Eigen::Vector3d(0.0, -1.0, 0.0);
  }
  o.colour_bar = !a.no_colour_bar;
  try {
    o.Check();
  } catch (const Error& e) {
    throw Error(std::string(e.what()) +
                " (check --range, --point-size, --size, --max-points, --up)");
  }
  return o;
}

mapping::ReconstructionOptions LogOptionsFrom(const ViewArgs& a) {
  mapping::ReconstructionOptions o;
  if (!a.method.empty()) {
    o.method = scanner::ParseTriangulationMethod(a.method);
    if (!o.method) throw Error("--method: unknown '" + a.method + "' (use plane, cone or ray)");
  }
  o.table_cache = TableCache();
  return o;
}

void RunFollow(const ViewArgs& a, const viewer::RenderOptions& render) {
  if (a.files.size() != 1) throw Error("--follow: give exactly one dive log");
  viewer::LiveViewOptions live;
  live.render = render;
  live.point_budget = a.max_points;
  live.decay_s = a.decay_s;
  live.offscreen = !a.screenshot.empty();
  if (live.offscreen && a.frames <= 0 && a.timeout_s <= 0.0) {
    throw Error(
        "--follow --screenshot: say when to take the picture with --frames N (or --timeout S)");
  }
  viewer::LiveView view(live);
  if (!a.screenshot.empty()) view.SetFinalScreenshot(a.screenshot);
  viewer::FollowOptions follow;
  follow.reconstruction = LogOptionsFrom(a);
  follow.stop_after_frames = a.frames;
  follow.timeout_s = a.timeout_s;
  viewer::FollowStatus status;
  {
    viewer::DiveLogFollower follower(a.files[0], follow, view);
    view.Run("uwscan view --follow " + a.files[0]);
    status = follower.status();
  }
  if (!status.error.empty()) throw Error(status.error);
  const viewer::LiveViewStats stats = view.stats();
  std::printf(
      "%s: followed %lld frames, %lld points (%zu held, %lld clouds dropped by the budget or "
      "decay)\n",
      a.files[0].c_str(), static_cast<long long>(status.frames),
      static_cast<long long>(status.points), stats.points_held,
      static_cast<long long>(stats.clouds_dropped));
  if (!a.screenshot.empty()) std::printf("%s: written\n", a.screenshot.c_str());
}

// A scene alone: its objects' surfaces, each where the scene places it.
void AddSceneObjects(const scanner::sim::Scene& loaded, const std::string& file,
                     viewer::Scene& scene) {
  std::size_t spheres = 0;
  for (const scanner::sim::SceneObject& object : loaded.objects) {
    if (object.shape ==
        scanner::sim::ObjectShape::kSphere) {  // ray cast exactly: it has no triangles
      ++spheres;
      continue;
    }
    scene.meshes.push_back({object.name, object.mesh, object.T_W_O});
  }
  if (scene.meshes.empty())
    throw Error(file + ": no object with a surface to draw (spheres are not drawn)");
  std::printf("%s: %zu object%s drawn", file.c_str(), scene.meshes.size(),
              scene.meshes.size() == 1 ? "" : "s");
  if (spheres > 0) std::printf(" (%zu sphere%s not drawn)", spheres, spheres == 1 ? "" : "s");
  std::printf("\n");
}

void RunView(const ViewArgs& a) {
  if (a.files.empty() && a.scene.empty()) {
    throw CLI::RequiredError(
        "files to show (or --scene SCENE.yaml alone, to show a scene's objects)");
  }
  const viewer::RenderOptions render = RenderOptionsFrom(a);
  std::vector<std::filesystem::path> inputs(a.files.begin(), a.files.end());
  if (!a.scene.empty()) inputs.emplace_back(a.scene);
  // Before minutes of reading and reconstructing, not after: the screenshot's path, the inputs
  // (a mistyped name says so even without a display; a followed log may not be there yet), and
  // the display.
  if (!a.screenshot.empty()) CheckOutputPath(a.screenshot, "--screenshot", inputs);
  for (const std::filesystem::path& input : inputs) {
    if (!a.follow && !std::filesystem::exists(input))
      throw Error(input.string() + ": no such file");
  }
  viewer::RequireDisplay();
  if (a.follow) {
    if (!a.scene.empty())
      throw Error("--scene: not with --follow (a followed log carries its own truth)");
    return RunFollow(a, render);
  }
  viewer::Scene scene;
  viewer::MapReportDrawing map_drawing;
  map_drawing.ellipsoid_every = a.ellipsoid_every;
  const mapping::ReconstructionOptions log_options = LogOptionsFrom(a);
  for (const std::string& file : a.files) {
    if (viewer::KindOfFile(file) == viewer::FileKind::kDiveLog) {
      const viewer::DiveLogSummary s = viewer::AddDiveLog(file, log_options, scene);
      std::printf("%s: %zu points from %lld frames, %s frame%s\n", file.c_str(), s.points,
                  static_cast<long long>(s.frames), s.world_frame ? "world" : "camera",
                  s.has_truth ? (", mean error against truth " +
                                 std::to_string(s.truth_mean_error_m * 1e3) + " mm")
                                    .c_str()
                              : "");
    } else {
      viewer::AddFile(file, log_options, map_drawing, scene);
    }
  }
  if (a.files.empty()) {
    AddSceneObjects(scanner::sim::LoadScene(a.scene), a.scene, scene);
  } else if (!a.scene.empty()) {
    const scanner::sim::RayCaster truth(scanner::sim::LoadScene(a.scene).objects);
    const std::size_t filled = viewer::SetSurfaceError(truth, kSurfaceSearch_m, scene);
    const std::size_t own = scene.clouds.size() - filled;
    const std::string kept =
        own == 0 ? ""
                 : ", " + std::to_string(own) +
                       " keep the error they carry (a simulated log's, from its truth)";
    std::printf("%s: %zu cloud%s coloured by the distance to its surfaces%s\n", a.scene.c_str(),
                filled, filled == 1 ? "" : "s", kept.c_str());
  }
  if (a.screenshot.empty()) {
    viewer::ShowScene(scene, render, "uwscan view");
    return;
  }
  const viewer::PictureInfo info = viewer::SaveScreenshot(scene, render, a.screenshot);
  std::printf("%s: %dx%d", a.screenshot.c_str(), info.width_px, info.height_px);
  if (info.points_total > 0) {  // meshes and trajectories alone have no points to colour
    std::printf(", %zu of %zu points drawn, colour by %s", info.points_drawn, info.points_total,
                viewer::ToString(render.colour));
    if (info.range) std::printf(" (%.4g .. %.4g)", info.range->lo, info.range->hi);
  }
  std::printf("\n");
}

}  // namespace

void AddViewCommand(CLI::App& app) {
  auto a = std::make_shared<ViewArgs>();
  CLI::App* cmd = app.add_subcommand(
      "view",
      std::string(
          "show clouds (.ply .pcd .xyz), meshes (.ply .off .stl .obj), TUM trajectories "
          "(.txt .tum), dive logs (.db), map, recognition and change reports (.json); keys: ") +
          viewer::kViewKeys);
  cmd->add_option("files", a->files, "files to show (none with --scene: the scene's objects)");
  cmd->add_option(
      "--colour,--color", a->colour,
      "height, error (simulated dive logs, or clouds given --scene), intensity, object or "
      "deviation "
      "(change reports; default: object with a recognition report, deviation with a change "
      "report, error with --scene, else height)");
  cmd->add_option("--range", a->range, "fixed colour range LOW HIGH (metres for height and error)")
      ->expected(2);
  cmd->add_option("--point-size", a->point_size_px, "point size in pixels");
  cmd->add_flag("--edl", a->edl,
                "Eye-Dome Lighting: shades points by depth so shapes read without colour");
  cmd->add_option("--camera", a->camera, "fit, top or side");
  cmd->add_option("--size", a->size, "window or picture size WIDTHxHEIGHT (default 1280x960)");
  cmd->add_option("--max-points", a->max_points,
                  "point budget: above it every k-th point is drawn; with --follow, points held");
  cmd->add_option(
         "--up", a->up,
         "the world's up direction X Y Z (default 0 0 -1: NED; 0 -1 0 with a recognition report, "
         "whose scan is in the sensor's frame)")
      ->expected(3);
  cmd->add_option("--method", a->method, "dive logs: plane, cone or ray (default: the scanner's)");
  cmd->add_option("--scene", a->scene,
                  "a simulated scene (.yaml): colour the clouds (e.g. a map of a dive simulated "
                  "from it) by their "
                  "distance to its true surfaces; alone, draw its objects")
      ->check(CLI::ExistingFile);
  cmd->add_option("--screenshot", a->screenshot, "render offscreen into this PNG and exit");
  cmd->add_flag("--no-colour-bar", a->no_colour_bar, "no colour bar");
  cmd->add_option("--ellipsoid-every", a->ellipsoid_every,
                  "map reports: a 3-sigma ellipsoid every N poses")
      ->check(kPositiveNumber);
  cmd->add_flag("--follow", a->follow,
                "show a dive log while it is written (waits for it to appear)");
  cmd->add_option("--frames", a->frames, "--follow: stop once the log holds N frames")
      ->check(kNonNegativeNumber);
  cmd->add_option("--timeout", a->timeout_s,
                  "--follow: fail after S seconds without the log or a new frame")
      ->check(kNonNegativeNumber);
  cmd->add_option("--decay", a->decay_s, "--follow: drop points older than S seconds (0: keep)")
      ->check(kNonNegativeNumber);
  cmd->callback([a] { RunView(*a); });
}

}  // namespace uwscan::app
