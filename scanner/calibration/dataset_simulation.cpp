#include "scanner/calibration/dataset_simulation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <random>

#include "scanner/calibration/calibration_dataset.hpp"
#include "scanner/calibration/calibration_yaml.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/parallel_tasks.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/effective_scanner.hpp"
#include "scanner/sim/imr_objects.hpp"
#include "scanner/sim/simulator.hpp"

namespace uwscan::scanner::calibration {
namespace {

namespace fs = std::filesystem;

constexpr int kMaxPoseDraws = 5000;
// Pose acceptance: the pattern's outline this far inside the image (fraction of its width),
// and its squares at least this large in the image, where the corner finders work reliably.
constexpr double kImageMarginFraction = 0.02;
constexpr double kMinSquarePx = 12.0;
// Board centres for the laser steps: the laser's aim at the drawn depth, moved across by up to
// this fraction of the board's size, so the light falls on different parts of the board.
constexpr double kAimSpreadFraction = 0.25;

std::uint64_t SplitMix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}
// Independent seeds for each purpose (a) and item (b) from the scene seed.
std::uint64_t Seed(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0) {
  return SplitMix(SplitMix(seed ^ SplitMix(a + 1)) ^ (b + 0x5851F42D4C957F2Dull));
}

// The scanner with its camera shrunk by `scale`: pixel grid and intrinsics together, so the
// field of view and the distortion (in normalised coordinates) stay; pixel edges keep their
// places, hence c' = (c + 1/2) s - 1/2.
void ScaleCamera(double scale, Scanner* scanner) {
  PinholeCamera& camera = scanner->camera().camera;
  const int w = camera.width_px, h = camera.height_px;
  const int w2 = std::max(1, static_cast<int>(std::lround(w * scale)));
  const int h2 = std::max(1, static_cast<int>(std::lround(h * scale)));
  const double sx = static_cast<double>(w2) / w, sy = static_cast<double>(h2) / h;
  camera.width_px = w2;
  camera.height_px = h2;
  camera.fx_px *= sx;
  camera.fy_px *= sy;
  camera.cx_px = (camera.cx_px + 0.5) * sx - 0.5;
  camera.cy_px = (camera.cy_px + 0.5) * sy - 0.5;
}

// The initial scanner the manifest names: the scene's file, with the sections earlier steps
// would have calibrated taken from the true scanner, and the camera scaled like the truth's.
std::string InitialScannerText(const CalibrationScene& cs) {
  Scanner initial = LoadScanner(*cs.initial_scanner);
  std::string comment = "Initial scanner for a " + cs.step +
                        " calibration: " + cs.initial_scanner->filename().string();
  if (!cs.initial_true_sections.empty()) {
    std::string names;
    for (const std::string& section : cs.initial_true_sections) {
      try {
        CopySection(cs.scene.scanner.model, section, &initial);
      } catch (const Error& e) {
        throw Error(cs.initial_scanner->string() + ": true section from " +
                    cs.scene.scanner.file.string() + ": " + e.what());
      }
      names += (names.empty() ? "" : ", ") + section;
    }
    comment +=
        " with " + names + " from the true scanner " + cs.scene.scanner.file.filename().string();
  }
  if (cs.image_scale != 1.0) {
    ScaleCamera(cs.image_scale, &initial);
    comment += ", its camera scaled by image_scale " + calibration_yaml::Shortest(cs.image_scale);
  }
  return ScannerToYaml(initial, comment);
}

void PrepareFolder(const fs::path& folder) {
  std::error_code error;
  if (fs::exists(folder, error)) {
    if (!fs::is_directory(folder)) throw Error(folder.string() + ": exists and is not a folder");
    if (!fs::is_empty(folder)) {
      throw Error(folder.string() +
                  ": exists and is not empty; a calibration dataset is written into a new or "
                  "empty folder only");
    }
    return;
  }
  fs::create_directories(folder, error);
  if (error) throw Error(folder.string() + ": cannot create: " + error.message());
}

void WriteImage(const fs::path& path, const StripeFrame& frame) {
  const bool mono8 = frame.format == PixelFormat::kMono8;
  const cv::Mat pixels(frame.height_px, frame.width_px, mono8 ? CV_8UC1 : CV_16UC1,
                       mono8 ? static_cast<void*>(const_cast<std::uint8_t*>(frame.mono8.data()))
                             : static_cast<void*>(const_cast<std::uint16_t*>(frame.mono16.data())));
  bool written = false;
  try {
    written = cv::imwrite(path.string(), pixels);
  } catch (const cv::Exception& e) {
    throw Error(path.string() + ": cannot write image: " + e.what());
  }
  if (!written) throw Error(path.string() + ": cannot write image");
}

std::string Name(const char* format, int a, int b = 0) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, a, b);
  return buffer;
}

std::string StripeImageName(int plane, int step) {
  return Name(step < 0 ? "plane_%02d_step_m%03d.png" : "plane_%02d_step_p%03d.png", plane,
              std::abs(step));
}

// Where a ray in water meets the board's front: the point in {C} and in {O}.
struct BoardHit {
  Eigen::Vector3d p_C;
  Eigen::Vector2d p_O;
};
std::optional<BoardHit> HitBoard(const Ray& ray, const Eigen::Isometry3d& T_C_O,
                                 const BoardGeometry& board) {
  const Eigen::Vector3d normal = T_C_O.linear().col(2);
  const double along = normal.dot(ray.direction);
  if (!(along > 1e-9)) return std::nullopt;  // parallel, or the board's back
  const double t = normal.dot(T_C_O.translation() - ray.origin) / along;
  if (!(t > 0.0)) return std::nullopt;
  const Eigen::Vector3d p_C = ray.At(t);
  const Eigen::Vector2d p_O = (T_C_O.inverse() * p_C).head<2>();
  if (!board.Contains(p_O)) return std::nullopt;
  return BoardHit{p_C, p_O};
}

// Everything the pose draws and the images need about the scene.
struct Setup {
  const CalibrationScene& cs;
  Scanner truth;  // effective scanner (scaled)
  RefractiveCamera camera;
  std::optional<GalvoScannerModel> galvo;
  std::optional<MemsScannerModel> mems;
  BoardGeometry board;
  sim::Scene scene;  // the scene with the scaled scanner
};

bool InImage(const PinholeCamera& camera, const Eigen::Vector2d& px, double margin_px) {
  return px.x() >= margin_px - 0.5 && px.y() >= margin_px - 0.5 &&
         px.x() <= camera.width_px - 0.5 - margin_px &&
         px.y() <= camera.height_px - 0.5 - margin_px;
}

// The pattern fully in the image, its squares large enough to be found.
bool PatternVisible(const Setup& s, const Eigen::Isometry3d& T_C_O) {
  const PinholeCamera& camera = s.camera.camera;
  const double margin = kImageMarginFraction * camera.width_px;
  for (const Eigen::Vector3d& p_O : s.cs.pattern.CornerPoints_O()) {
    const std::optional<Eigen::Vector2d> px = s.camera.ProjectPointInWater(T_C_O * p_O);
    if (!px || !InImage(camera, *px, margin)) return false;
  }
  const Eigen::AlignedBox2d extent = PatternExtent_O(s.cs.pattern);
  Eigen::Vector2d outline[4];
  const Eigen::AlignedBox2d::CornerType kCorners[4] = {
      Eigen::AlignedBox2d::BottomLeft, Eigen::AlignedBox2d::BottomRight,
      Eigen::AlignedBox2d::TopRight, Eigen::AlignedBox2d::TopLeft};
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector2d corner = extent.corner(kCorners[k]);
    const std::optional<Eigen::Vector2d> px =
        s.camera.ProjectPointInWater(T_C_O * Eigen::Vector3d(corner.x(), corner.y(), 0.0));
    if (!px || !InImage(camera, *px, margin)) return false;
    outline[k] = *px;
  }
  const double squares[2] = {extent.sizes().x() / s.cs.pattern.square_m,
                             extent.sizes().y() / s.cs.pattern.square_m};
  for (int k = 0; k < 4; ++k) {
    if ((outline[(k + 1) % 4] - outline[k]).norm() / squares[k % 2] < kMinSquarePx) return false;
  }
  return true;
}

struct Dot {
  int index = 0;  // in the grid, row by row, x fastest
  Eigen::Vector2d volts;
  Eigen::Vector2d px;
  double sigma_px = 1.0;
  double amplitude = 0.0;
};

// The grid's dots that land on the board and well inside the image.
std::vector<Dot> DotsOnBoard(const Setup& s, const Eigen::Isometry3d& T_C_O) {
  const CalibrationScene& cs = s.cs;
  const sim::SimulationEffects& effects = s.scene.effects;
  const sim::SimulationEffects::Beam beam =
      effects.beam.on ? effects.beam : sim::SimulationEffects::Beam{};
  const double max_volts = cs.volts_fraction * s.mems->laser.max_volts;
  std::vector<Dot> dots;
  for (int j = 0; j < cs.volts_grid.y(); ++j) {
    for (int i = 0; i < cs.volts_grid.x(); ++i) {
      auto spread = [&](int k, int n) {
        return n == 1 ? 0.0 : max_volts * (2.0 * k / (n - 1) - 1.0);
      };
      Dot dot;
      dot.index = j * cs.volts_grid.x() + i;
      dot.volts = Eigen::Vector2d(spread(i, cs.volts_grid.x()), spread(j, cs.volts_grid.y()));
      const RayTrace beam_ray = s.mems->laser.RayInWater(dot.volts);
      if (!beam_ray.ok()) continue;
      const std::optional<BoardHit> hit = HitBoard(beam_ray.ray, T_C_O, s.board);
      if (!hit) continue;
      const std::optional<Eigen::Vector2d> px = s.camera.ProjectPointInWater(hit->p_C);
      if (!px) continue;
      // The footprint (1/e^2 diameter = 4 sigma) grows with the path in water; its size in the
      // image is that of sigma on the board, projected (so the viewport magnifies it too), and
      // the optics blur it further. Kept round: its stretch on a tilted board is ignored.
      const double path_m = (hit->p_C - beam_ray.ray.origin).norm();
      const double sigma_m = 0.25 * (beam.diameter_m + beam.divergence_rad * path_m);
      double footprint_px = 0.0;
      for (int axis = 0; axis < 2; ++axis) {
        const std::optional<Eigen::Vector2d> side =
            s.camera.ProjectPointInWater(hit->p_C + sigma_m * T_C_O.linear().col(axis));
        if (side) footprint_px += 0.5 * (*side - *px).norm();
      }
      dot.sigma_px = std::hypot(footprint_px, effects.image.blur_sigma_px);
      const double reach = 4.0 * dot.sigma_px + 1.0;
      if (!InImage(s.camera.camera, *px, reach)) continue;
      // As bright as the simulator's stripes: Lambertian paper, the reference target's
      // reflectance 0.5, inverse-square falloff, attenuation when that stage is on.
      const double cos_incidence = std::abs(T_C_O.linear().col(2).dot(beam_ray.ray.direction));
      const double range_m = std::max(hit->p_C.norm(), 0.05);
      dot.amplitude = effects.image.peak_level * (cs.board_reflectance / 0.5) * cos_incidence /
                      (range_m * range_m);
      if (effects.attenuation) {
        dot.amplitude *= std::exp(-s.scene.water.attenuation_per_m * (path_m + range_m));
      }
      dot.px = *px;
      dots.push_back(dot);
    }
  }
  return dots;
}

// Every mirror step's central laser ray meets the board and is seen: each stripe lies on it.
bool StripesOnBoard(const Setup& s, const Eigen::Isometry3d& T_C_O) {
  for (const int step : s.cs.mirror_steps) {
    const RayTrace ray = s.galvo->laser.FanAtStep(step).RayInWater(0.0);
    if (!ray.ok()) return false;
    const std::optional<BoardHit> hit = HitBoard(ray.ray, T_C_O, s.board);
    if (!hit) return false;
    const std::optional<Eigen::Vector2d> px = s.camera.ProjectPointInWater(hit->p_C);
    if (!px || !InImage(s.camera.camera, *px, 0.0)) return false;
  }
  return true;
}

// Draws board poses until one meets the step's conditions.
Eigen::Isometry3d DrawPose(const Setup& s, std::mt19937_64& rng, bool plane) {
  const CalibrationScene& cs = s.cs;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
  const int min_dots = std::max(1, cs.volts_grid.prod() / 4);
  for (int draw = 0; draw < kMaxPoseDraws; ++draw) {
    const double depth = uniform(cs.distance_m.x(), cs.distance_m.y());
    // Where the board's centre goes: through the middle of the image for views, where the
    // laser points for planes.
    RayTrace aim;
    if (!plane) {
      const PinholeCamera& c = s.camera.camera;
      const double u = uniform(0.3, 0.7) * c.width_px;  // one draw per statement: a fixed order
      const double v = uniform(0.3, 0.7) * c.height_px;
      aim = s.camera.PixelToRayInWater(Eigen::Vector2d(u, v));
    } else if (s.galvo) {
      const auto [lo, hi] = std::minmax_element(cs.mirror_steps.begin(), cs.mirror_steps.end());
      aim = s.galvo->laser.FanAtStep((*lo + *hi) / 2).RayInWater(0.0);
    } else {
      aim = s.mems->laser.RayInWater(Eigen::Vector2d::Zero());
    }
    if (!aim.ok() || !(aim.ray.direction.z() > 1e-6)) continue;
    Eigen::Vector3d centre_C = aim.ray.At((depth - aim.ray.origin.z()) / aim.ray.direction.z());
    if (plane) {
      centre_C.x() += kAimSpreadFraction * s.board.size_m.x() * uniform(-1.0, 1.0);
      centre_C.y() += kAimSpreadFraction * s.board.size_m.y() * uniform(-1.0, 1.0);
    }
    // Facing the camera (z_O along the line of sight, x_O as close to x_C as it goes), then
    // tilted about a random axis across the line of sight and rolled about the normal.
    const Eigen::Vector3d z = centre_C.normalized();
    const Eigen::Vector3d x = (Eigen::Vector3d::UnitX() - z * z.x()).normalized();
    const Eigen::Vector3d y = z.cross(x);
    Eigen::Matrix3d facing;
    facing << x, y, z;
    const double azimuth = uniform(0.0, 2.0 * M_PI);
    const Eigen::Vector3d axis = std::cos(azimuth) * x + std::sin(azimuth) * y;
    Eigen::Isometry3d T_C_centre = Eigen::Isometry3d::Identity();
    const double tilt = uniform(0.0, cs.max_tilt_rad);
    const double roll = uniform(-cs.max_roll_rad, cs.max_roll_rad);
    T_C_centre.linear() = Eigen::AngleAxisd(tilt, axis).toRotationMatrix() * facing *
                          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    T_C_centre.translation() = centre_C;
    Eigen::Isometry3d T_C_O =
        T_C_centre * Eigen::Translation3d(-s.board.centre_O.x(), -s.board.centre_O.y(), 0.0);
    if (!PatternVisible(s, T_C_O)) continue;
    if (plane && s.galvo && !StripesOnBoard(s, T_C_O)) continue;
    if (plane && s.mems && static_cast<int>(DotsOnBoard(s, T_C_O).size()) < min_dots) continue;
    return T_C_O;
  }
  std::string what = "every corner of the pattern in the image with squares of at least " +
                     std::to_string(static_cast<int>(kMinSquarePx)) + " px";
  if (plane && s.galvo) what += ", and the stripe of every mirror step on the board";
  if (plane && s.mems) what += ", and at least a quarter of the voltage grid's dots on the board";
  throw Error(cs.scene.source + ": no board pose among " + std::to_string(kMaxPoseDraws) +
              " random draws has " + what +
              "; change calibration.distance_m, max_tilt_rad, the pattern, board_size_m or " +
              (s.galvo ? "mirror_steps" : "image_scale"));
}

// The scene with its camera scaled, and the effective scanner the images are made from.
Setup MakeSetup(const CalibrationScene& cs) {
  Setup s{cs, {}, {}, {}, {}, BoardOf(cs.pattern, cs.board_size_m), cs.scene};
  if (cs.image_scale != 1.0) ScaleCamera(cs.image_scale, &s.scene.scanner.model);
  s.truth = sim::EffectiveScanner(s.scene);
  s.camera = s.truth.camera();
  if (s.truth.kind() == ScannerKind::kGalvo) {
    s.galvo = s.truth.galvo();
  } else {
    s.mems = s.truth.mems();
  }
  return s;
}

// Images the dataset holds at most: one pattern image per pose and, per plane, one per mirror
// step or voltage pair. The fraction of them written is the progress.
double ImageCount(const Setup& s, int poses, bool views) {
  const int per_pose = views     ? 1
                       : s.galvo ? 1 + static_cast<int>(s.cs.mirror_steps.size())
                                 : 1 + s.cs.volts_grid.prod();
  return static_cast<double>(poses) * per_pose;
}

// Counts the images written and reports the fraction done, one call at a time (the images are
// written by OpenMP worker threads).
class ProgressCounter {
 public:
  ProgressCounter(const std::function<void(double)>& progress, double total)
      : progress_(progress), total_(total) {}

  void Add(int images) {
    const std::lock_guard<std::mutex> lock(mutex_);
    written_ += images;
    if (progress_) progress_(std::min(1.0, written_ / total_));
  }

 private:
  const std::function<void(double)>& progress_;
  const double total_;
  int written_ = 0;
  std::mutex mutex_;
};

// The manifest's fields known before any image: folder, step, pattern, image size.
CalibrationDataset DatasetHeader(const Setup& s, const fs::path& out_folder) {
  CalibrationDataset dataset;
  dataset.folder = out_folder;
  dataset.step = s.cs.step;
  dataset.pattern = s.cs.pattern;
  dataset.width_px = s.camera.camera.width_px;
  dataset.height_px = s.camera.camera.height_px;
  return dataset;
}

// Pose p's pattern image (lights on, laser off); returns its file name.
std::string WritePatternImage(const Setup& s, const TargetRenderer& renderer,
                              TargetRenderOptions render, const Eigen::Isometry3d& T_C_O, int p,
                              bool views, const fs::path& out_folder) {
  render.seed = Seed(s.cs.scene.seed, 1, static_cast<std::uint64_t>(p));
  const StripeFrame pattern = renderer.Render(s.cs.pattern, T_C_O, render);
  const std::string name = Name(views ? "view_%03d.png" : "plane_%02d.png", p);
  WriteImage(out_folder / name, pattern);
  return name;
}

// The board as the simulator's only object: a plane of the board's size and reflectance.
sim::SceneObject BoardObject(const Setup& s, const Eigen::Isometry3d& T_C_O) {
  sim::SceneObject board;
  board.name = "board";
  board.shape = sim::ObjectShape::kPlane;
  board.mesh = sim::MakeRectangle(s.board.size_m.x(), s.board.size_m.y());
  board.T_W_O = T_C_O * Eigen::Translation3d(s.board.centre_O.x(), s.board.centre_O.y(), 0.0);
  board.reflectance = s.cs.board_reflectance;
  return board;
}

// The scene the simulator renders pose p's stripes in: the board alone, the lights off, one
// sweep over the imaged mirror steps (frame k is step step_min + k).
sim::Scene StripeScene(const Setup& s, const Eigen::Isometry3d& T_C_O, int p) {
  const CalibrationScene& cs = s.cs;
  sim::Scene lit = s.scene;
  lit.objects = {BoardObject(s, T_C_O)};
  lit.scanner.galvo.step_min = *std::min_element(cs.mirror_steps.begin(), cs.mirror_steps.end());
  lit.scanner.galvo.step_max = *std::max_element(cs.mirror_steps.begin(), cs.mirror_steps.end());
  lit.scanner.galvo.step_stride = 1;
  lit.scanner.sweeps = 1;
  if (!lit.effects.AnyImageStage()) lit.effects.image.on = true;
  lit.seed = Seed(cs.scene.seed, 2, static_cast<std::uint64_t>(p));
  return lit;
}

// Pose p's stripe images, one per mirror step; returns the manifest's (image, step) list.
std::vector<std::pair<std::string, int>> WriteStripeImages(const Setup& s,
                                                           const Eigen::Isometry3d& T_C_O, int p,
                                                           const fs::path& out_folder,
                                                           ProgressCounter& done) {
  const std::vector<int>& steps = s.cs.mirror_steps;
  const sim::Scene lit = StripeScene(s, T_C_O, p);
  const int step_min = lit.scanner.galvo.step_min;
  const sim::Simulator simulator(lit);
  RunParallelTasks(std::ssize(steps), 0, [&](std::ptrdiff_t k) {
    const int step = steps[static_cast<size_t>(k)];
    const sim::SimulatedFrame frame = simulator.Frame(step - step_min);
    WriteImage(out_folder / StripeImageName(p, step), *frame.image);
    done.Add(1);
  });
  std::vector<std::pair<std::string, int>> stripes;
  for (const int step : steps) stripes.emplace_back(StripeImageName(p, step), step);
  return stripes;
}

// Lights off: the ambient level and read noise of the scene's image stages.
TargetRenderOptions DarkImage(const sim::SimulationEffects& effects) {
  TargetRenderOptions dark;
  dark.format = effects.image.format;
  dark.black_level = effects.ambient.on ? effects.ambient.level : 0.0;
  dark.white_level = MaxPixelValue(dark.format);
  dark.noise_sigma = effects.sensor_noise.on ? effects.sensor_noise.read_sigma : 0.0;
  return dark;
}

// Pose p's dot images, one per voltage pair whose dot lands on the board and in the image;
// returns the manifest's (image, volts) list.
std::vector<std::pair<std::string, Eigen::Vector2d>> WriteDotImages(const Setup& s,
                                                                    const Eigen::Isometry3d& T_C_O,
                                                                    int p,
                                                                    const fs::path& out_folder,
                                                                    ProgressCounter& done) {
  const TargetRenderOptions dark = DarkImage(s.scene.effects);
  const std::vector<Dot> dots = DotsOnBoard(s, T_C_O);
  RunParallelTasks(std::ssize(dots), 0, [&](std::ptrdiff_t k) {
    const Dot& dot = dots[static_cast<size_t>(k)];
    TargetRenderOptions options = dark;
    options.seed = Seed(s.cs.scene.seed, 3, static_cast<std::uint64_t>(p) * 1000003u + dot.index);
    const StripeFrame image = RenderDot(s.camera.camera.width_px, s.camera.camera.height_px, dot.px,
                                        dot.sigma_px, dot.amplitude, options);
    WriteImage(out_folder / Name("plane_%02d_dot_%03d.png", p, dot.index), image);
    done.Add(1);
  });
  // Voltage pairs whose dot missed the board or the image count as done, unwritten.
  done.Add(s.cs.volts_grid.prod() - static_cast<int>(dots.size()));
  std::vector<std::pair<std::string, Eigen::Vector2d>> named;
  for (const Dot& dot : dots) {
    named.emplace_back(Name("plane_%02d_dot_%03d.png", p, dot.index), dot.volts);
  }
  return named;
}

// initial_scanner.yaml when the scene names an initial scanner; returns its path.
std::optional<fs::path> WriteInitialScanner(const CalibrationScene& cs,
                                            const fs::path& out_folder) {
  if (!cs.initial_scanner) return std::nullopt;
  const fs::path initial = out_folder / "initial_scanner.yaml";
  std::ofstream out(initial);
  out << InitialScannerText(cs);
  if (!out) throw Error(initial.string() + ": cannot write");
  return initial;
}

}  // namespace

void SimulateCalibrationDataset(const CalibrationScene& cs, const fs::path& out_folder,
                                const std::function<void(double)>& progress) {
  cs.Check();
  const Setup s = MakeSetup(cs);
  PrepareFolder(out_folder);
  const bool views = cs.step == "intrinsics" || cs.step == "viewport";
  const int poses = views ? cs.views : cs.planes;
  ProgressCounter done(progress, ImageCount(s, poses, views));
  CalibrationDataset dataset = DatasetHeader(s, out_folder);
  DatasetTruth truth;
  truth.scanner = s.truth;
  const TargetRenderer renderer(s.camera);
  TargetRenderOptions render = cs.render;
  render.board_size_m = s.board.size_m;
  std::mt19937_64 rng(Seed(cs.scene.seed, 0));

  for (int p = 0; p < poses; ++p) {
    const Eigen::Isometry3d T_C_O = DrawPose(s, rng, !views);
    const std::string name = WritePatternImage(s, renderer, render, T_C_O, p, views, out_folder);
    done.Add(1);
    if (views) {
      dataset.views.push_back(name);
      truth.T_C_O_views.push_back(T_C_O);
      continue;
    }
    CalibrationDataset::Plane plane;
    plane.pattern_image = name;
    truth.T_C_O_planes.push_back(T_C_O);
    if (s.galvo) {
      plane.stripes = WriteStripeImages(s, T_C_O, p, out_folder, done);
    } else {
      plane.dots = WriteDotImages(s, T_C_O, p, out_folder, done);
    }
    dataset.planes.push_back(std::move(plane));
  }

  dataset.scanner_file = WriteInitialScanner(cs, out_folder);
  dataset.water_refractive_index = cs.scene.water.refractive_index;
  dataset.truth_file = out_folder / "truth.yaml";
  WriteDatasetTruth(*dataset.truth_file, truth);
  WriteCalibrationManifest(dataset);
}

void SimulateCalibrationDataset(const fs::path& calibration_scene, const fs::path& out_folder,
                                const std::function<void(double)>& progress) {
  SimulateCalibrationDataset(LoadCalibrationScene(calibration_scene), out_folder, progress);
}

}  // namespace uwscan::scanner::calibration
