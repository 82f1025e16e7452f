#include "bench/change/change_benchmark.hpp"

#include <fcntl.h>
#include <omp.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <tuple>

#include "bench/scratch_folder.hpp"
#include "mapping/change/compare_surveys.hpp"
#include "mapping/log/dive_log.hpp"
#include "mapping/log/dive_simulation.hpp"
#include "mapping/slam/dive_mapping.hpp"
#include "perception/cloud/cloud_io.hpp"
#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/preprocessing/voxel_filter.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/common/triangle_mesh.hpp"
#include "scanner/sim/ray_caster.hpp"
#include "scanner/sim/scene.hpp"
#include "scanner/sim/scene_mesh.hpp"
#include "scanner/sim/simulator.hpp"

extern char** environ;

namespace uwscan::bench {
namespace {

namespace fs = std::filesystem;
using mapping::CoreDeviation;
using mapping::SurfaceStatus;
using perception::PointCloud;
using Clock = std::chrono::steady_clock;

constexpr double kSpacing_m = 0.01;  // every method is judged on points this far apart
constexpr double kSurfaceSearch_m = 0.05;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string ReadText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot read");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// One survey: the scene dived (simulated into a log), the log mapped by SLAM.
struct Epoch {
  scanner::sim::Scene scene;
  mapping::Survey map;
  double map_rms_m = 0.0;
};

double RmsToScene(const PointCloud& map, const scanner::sim::RayCaster& caster) {
  double sum2 = 0.0;
#pragma omp parallel for reduction(+ : sum2) schedule(static)
  for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(map.size()); ++i) {
    const double d =
        caster.DistanceToSurface(map.Point(static_cast<std::size_t>(i)), kSurfaceSearch_m)
            .value_or(kSurfaceSearch_m);
    sum2 += d * d;
  }
  return std::sqrt(sum2 / static_cast<double>(map.size()));
}

Epoch SurveyEpoch(const fs::path& scene_path, const fs::path& folder,
                  const ChangeBenchOptions& options, const Progress& progress,
                  ChangeFigures& figures) {
  const std::string text = ReadText(scene_path);
  Epoch epoch{
      .scene = scanner::sim::ParseScene(text, scene_path.string(), scene_path.parent_path()),
      .map = {}};
  const std::string name = scene_path.stem().string();
  const fs::path log_path = folder / (name + ".db");
  const scanner::sim::Simulator simulator(epoch.scene);
  mapping::DiveSimulationOptions sim;
  sim.threads = options.threads;
  sim.producer = "uwscan bench change";
  figures.simulate_seconds += mapping::SimulateDive(simulator, text, log_path, sim, [&](double f) {
                                if (progress) progress("simulate " + name, f);
                              }).seconds;
  mapping::DiveMappingOptions map_options;
  map_options.mapper.threads = options.threads;
  map_options.table_cache = options.table_cache;
  const mapping::DiveLogReader log(log_path);
  const mapping::DiveMapping m = mapping::MapDive(log, map_options, [&](double f) {
    if (progress) progress("map " + name, f);
  });
  figures.map_seconds += m.seconds;
  epoch.map.name = name + " (SLAM map)";
  epoch.map.kind = mapping::SurveyKind::kMap;
  epoch.map.cloud = m.map;
  for (const mapping::TimedPose& p : m.slam) epoch.map.poses.push_back(p.T_W_V);
  epoch.map.pose_covariances = m.covariances;
  epoch.map.joint_uncertainty = m.joint_uncertainty;
  epoch.map_rms_m = RmsToScene(m.map, scanner::sim::RayCaster(epoch.scene.objects));
  return epoch;
}

// A change between the scenes: an object in one only (a disc of growth or loss), moved, or
// with part of its surface changed in place (a dent, a bolt head gone).
struct Change {
  std::vector<scanner::sim::SceneObject> footprints;  // the object where it was and where it is
  double depth_m = 0.0;                               // a disc's thickness; 0 for a moved object
  bool growth = false;
  bool disc = false;
  std::optional<Eigen::AlignedBox3d> part_O;  // the changed part, in the object's frame
};

bool SamePose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff() < 1e-9;
}

Change ChangeOf(const scanner::sim::SceneObject& object, bool growth) {
  Change c{.footprints = {object},
           .depth_m = 0.0,
           .growth = growth,
           .disc = object.shape == scanner::sim::ObjectShape::kCylinder,
           .part_O = std::nullopt};
  if (c.disc) {
    double lo = 1e300, hi = -1e300;
    for (const Eigen::Vector3d& v : object.mesh.vertices) {
      lo = std::min(lo, v.z());
      hi = std::max(hi, v.z());
    }
    c.depth_m = hi - lo;
  }
  return c;
}

// The volume a closed mesh encloses (the divergence theorem over its triangles).
double EnclosedVolume(const scanner::TriangleMesh& mesh) {
  double six_volume = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    six_volume += mesh.vertices[static_cast<std::size_t>(t[0])].dot(
        mesh.vertices[static_cast<std::size_t>(t[1])].cross(
            mesh.vertices[static_cast<std::size_t>(t[2])]));
  }
  return six_volume / 6.0;
}

// An object at the same pose in both scenes whose surface changed in place: the box around the
// vertices one mesh has and the other has not (the scenes build the two epochs' meshes alike
// elsewhere, imr_objects.hpp); std::nullopt when the meshes are the same.
std::optional<Change> ChangedInPlace(const scanner::sim::SceneObject& before,
                                     const scanner::sim::SceneObject& after) {
  const auto key = [](const Eigen::Vector3d& v) { return std::tuple(v.x(), v.y(), v.z()); };
  std::set<std::tuple<double, double, double>> in_before, in_after;
  for (const Eigen::Vector3d& v : before.mesh.vertices) in_before.insert(key(v));
  for (const Eigen::Vector3d& v : after.mesh.vertices) in_after.insert(key(v));
  Eigen::AlignedBox3d part;
  for (const Eigen::Vector3d& v : before.mesh.vertices)
    if (!in_after.count(key(v))) part.extend(v);
  for (const Eigen::Vector3d& v : after.mesh.vertices)
    if (!in_before.count(key(v))) part.extend(v);
  if (part.isEmpty()) return std::nullopt;
  return Change{.footprints = {after},
                .depth_m = 0.0,
                .growth = EnclosedVolume(after.mesh) > EnclosedVolume(before.mesh),
                .disc = false,
                .part_O = part};
}

std::vector<Change> ChangesBetween(const scanner::sim::Scene& before,
                                   const scanner::sim::Scene& after) {
  const auto find = [](const scanner::sim::Scene& s, const std::string& name) {
    const auto it =
        std::find_if(s.objects.begin(), s.objects.end(),
                     [&](const scanner::sim::SceneObject& o) { return o.name == name; });
    return it == s.objects.end() ? nullptr : &*it;
  };
  std::vector<Change> changes;
  for (const scanner::sim::SceneObject& o : after.objects) {
    const scanner::sim::SceneObject* old = find(before, o.name);
    if (!old) {
      changes.push_back(ChangeOf(o, true));
    } else if (SamePose(old->T_W_O, o.T_W_O)) {
      if (std::optional<Change> part = ChangedInPlace(*old, o)) changes.push_back(*part);
    } else {
      Change moved = ChangeOf(o, true);
      moved.disc = false;
      moved.footprints.push_back(*old);
      changes.push_back(moved);
    }
  }
  for (const scanner::sim::SceneObject& o : before.objects)
    if (!find(after, o.name)) changes.push_back(ChangeOf(o, false));
  return changes;
}

// Whether p lies on the change: within a disc's radius (and near its faces), within a changed
// part's box grown by 1 cm, or within an object's box grown by 2 cm.
bool OnChange(const Change& c, const Eigen::Vector3d& p_W) {
  for (const scanner::sim::SceneObject& o : c.footprints) {
    const Eigen::Vector3d p = o.T_W_O.inverse() * p_W;
    if (c.part_O) {
      const Eigen::Vector3d margin = Eigen::Vector3d::Constant(0.01);
      if ((p.array() >= (c.part_O->min() - margin).array()).all() &&
          (p.array() <= (c.part_O->max() + margin).array()).all())
        return true;
      continue;
    }
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    for (const Eigen::Vector3d& v : o.mesh.vertices) {
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
    if (c.disc) {
      if (p.head<2>().norm() <= 0.5 * (hi.x() - lo.x()) + 0.002 && p.z() >= lo.z() - 0.01 &&
          p.z() <= hi.z() + 0.01)
        return true;
    } else if ((p.array() >= lo.array() - 0.02).all() && (p.array() <= hi.array() + 0.02).all()) {
      return true;
    }
  }
  return false;
}

// Each point's change (index), -1 where nothing changed.
std::vector<int> TruthLabels(const std::vector<CoreDeviation>& points,
                             const std::vector<Change>& changes) {
  std::vector<int> label(points.size(), -1);
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (std::size_t k = 0; k < changes.size() && label[i] < 0; ++k)
      if (OnChange(changes[k], points[i].point_W)) label[i] = static_cast<int>(k);
  }
  return label;
}

// The same rule for every method (ChangeBenchOptions, MethodFigures).
MethodFigures Judge(const std::vector<CoreDeviation>& points, const std::vector<int>& label,
                    const std::vector<Change>& changes, bool signed_distance) {
  MethodFigures f;
  std::vector<int> region_of;
  mapping::FindChangeRegions(points, kSpacing_m, mapping::RegionOptions{}, region_of);
  std::vector<int> on(changes.size(), 0), found(changes.size(), 0);
  double unchanged = 0, flagged = 0, in_region = 0, sum2 = 0, changed = 0, error2 = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const CoreDeviation& d = points[i];
    if (d.status == SurfaceStatus::kNotInspected) continue;
    if (label[i] < 0) {
      unchanged += 1;
      flagged += d.status == SurfaceStatus::kChanged;
      in_region += region_of[i] >= 0;
      sum2 += d.deviation_m * d.deviation_m;
      continue;
    }
    const Change& c = changes[static_cast<std::size_t>(label[i])];
    ++on[static_cast<std::size_t>(label[i])];
    const bool right_sign = !signed_distance || (d.deviation_m > 0.0) == c.growth;
    found[static_cast<std::size_t>(label[i])] += region_of[i] >= 0 && right_sign;
    if (!c.disc) continue;
    const double truth = signed_distance ? (c.growth ? c.depth_m : -c.depth_m) : c.depth_m;
    changed += 1;
    error2 += (d.deviation_m - truth) * (d.deviation_m - truth);
  }
  f.unchanged_flagged_share = unchanged > 0 ? flagged / unchanged : 0.0;
  f.unchanged_rms_m = unchanged > 0 ? std::sqrt(sum2 / unchanged) : 0.0;
  f.changed_rms_error_m = changed > 0 ? std::sqrt(error2 / changed) : 0.0;
  const double false_share = unchanged > 0 ? in_region / unchanged : 0.0;
  for (std::size_t k = 0; k < changes.size(); ++k) {
    f.changes.push_back(
        {.name = changes[k].footprints.front().name + (changes[k].part_O ? " (surface)" : ""),
         .points = on[k],
         .found = on[k] > 0 ? static_cast<double>(found[k]) / on[k] : 0.0});
    if (!changes[k].disc || on[k] == 0) continue;  // never seen: not a detection to judge
    DepthFigures& depth = f.by_depth_mm[static_cast<int>(std::lround(changes[k].depth_m * 1e3))];
    depth.changes += 1;
    depth.detection_rate += 2 * found[k] >= on[k];
    depth.false_area_share = false_share;
  }
  for (auto& [mm, depth] : f.by_depth_mm) depth.detection_rate /= depth.changes;
  return f;
}

double FalseShare(const MethodFigures& f) {
  return f.by_depth_mm.empty() ? 0.0 : f.by_depth_mm.begin()->second.false_area_share;
}

// A plain distance judged at the threshold that gives it uwscan's false area (bisection: the
// false area falls as the threshold rises): its best single threshold at equal false area.
MethodFigures JudgeAtEqualFalseArea(std::vector<CoreDeviation> points,
                                    const std::vector<int>& label,
                                    const std::vector<Change>& changes, bool signed_distance,
                                    double target_false_share) {
  double lo = 0.0, hi = 0.05;
  MethodFigures best;
  for (int i = 0; i < 30; ++i) {
    const double threshold = 0.5 * (lo + hi);
    for (CoreDeviation& d : points) {
      if (d.status == SurfaceStatus::kNotInspected) continue;
      d.status =
          std::abs(d.deviation_m) > threshold ? SurfaceStatus::kChanged : SurfaceStatus::kUnchanged;
    }
    MethodFigures f = Judge(points, label, changes, signed_distance);
    f.threshold_m = threshold;
    if (FalseShare(f) > target_false_share) {
      lo = threshold;
    } else {
      hi = threshold;
      best = f;
    }
  }
  return best;
}

std::vector<CoreDeviation> AsPoints(const PointCloud& cloud, const std::vector<double>& distance) {
  std::vector<CoreDeviation> points(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    points[i].point_W = cloud.Point(i);
    points[i].deviation_m = distance[i];
    points[i].status =
        std::isfinite(distance[i]) ? SurfaceStatus::kUnchanged : SurfaceStatus::kNotInspected;
  }
  return points;
}

// Unsigned distance from each point to the nearest point of the reference.
std::vector<double> NearestDistances(const PointCloud& points, const PointCloud& reference) {
  const perception::KnnIndex index(reference.points);
  std::vector<double> out(points.size());
#pragma omp parallel
  {
    std::vector<std::uint32_t> k;
    std::vector<float> d2;
#pragma omp for schedule(static)
    for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(points.size()); ++i) {
      const Eigen::Vector3d p = points.Point(static_cast<std::size_t>(i));
      index.Query((p - reference.origin).cast<float>(), 1, k, d2);
      out[static_cast<std::size_t>(i)] = (reference.Point(k.front()) - p).norm();
    }
  }
  return out;
}

// ---- CloudCompare, run as its command line runs it (under Xvfb when there is no display).

bool CloudCompareInstalled() { return ::access("/usr/bin/CloudCompare", X_OK) == 0; }

// Runs CloudCompare with `arguments`, its output into `log`; its own timings summed (the
// distance computation alone, files and start-up excluded).
double RunCloudCompare(const std::vector<std::string>& arguments, const fs::path& log) {
  std::vector<std::string> argv;
  if (!std::getenv("DISPLAY")) argv = {"xvfb-run", "-a", "-s", "-screen 0 640x480x24"};
  argv.push_back("CloudCompare");
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  std::vector<char*> raw;
  for (std::string& a : argv) raw.push_back(a.data());
  raw.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, raw.front(), &actions, nullptr, raw.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) throw Error("bench change: cannot start " + argv.front());
  int status = 0;
  ::waitpid(pid, &status, 0);
  const std::string text = ReadText(log);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw Error("bench change: CloudCompare failed (" + log.string() + ")");
  static const std::regex timing(
      R"(\[(?:ComputeDistances|computeApproxDistances|DistanceComputationTools)[^\]]*\] Time: ([0-9.]+) s)");
  double seconds = 0.0;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), timing);
       it != std::sregex_iterator(); ++it)
    seconds += std::stod((*it)[1]);
  return seconds;
}

// The distances CloudCompare wrote (ASCII x y z d), put back on `points` by position (it may
// drop duplicate points while loading); NaN where it wrote none.
std::vector<double> ReadCloudCompareDistances(const fs::path& asc, const PointCloud& points) {
  std::vector<double> out(points.size(), std::numeric_limits<double>::quiet_NaN());
  const perception::KnnIndex index(points.points);
  std::ifstream in(asc);
  // CloudCompare exits with 0 on a command it refuses: the missing output tells.
  if (!in) throw Error("bench change: CloudCompare wrote no " + asc.string());
  std::string line;
  std::vector<std::uint32_t> k;
  std::vector<float> d2;
  while (std::getline(in, line)) {
    std::istringstream row(line);
    Eigen::Vector3d p;
    double d = 0.0;
    if (!(row >> p.x() >> p.y() >> p.z() >> d)) continue;
    index.Query((p - points.origin).cast<float>(), 1, k, d2);
    if (!k.empty() && d2.front() < 1e-8f) out[k.front()] = d;
  }
  return out;
}

// One CloudCompare distance from `points` (written to compared.ply) with `arguments` after it,
// its output read back from NAME.asc and judged at uwscan's false area.
MethodFigures CloudCompareMethod(const std::string& name, const std::vector<std::string>& arguments,
                                 bool signed_distance, const PointCloud& points,
                                 const fs::path& folder, const std::vector<int>& label,
                                 const std::vector<Change>& changes, double target_false_share) {
  std::vector<std::string> argv = {"-SILENT",
                                   "-AUTO_SAVE",
                                   "OFF",
                                   "-C_EXPORT_FMT",
                                   "ASC",
                                   "-PREC",
                                   "8",
                                   "-O",
                                   (folder / "compared.ply").string()};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  const double seconds = RunCloudCompare(argv, folder / (name + ".log"));
  MethodFigures f = JudgeAtEqualFalseArea(
      AsPoints(points, ReadCloudCompareDistances(folder / (name + ".asc"), points)), label, changes,
      signed_distance, target_false_share);
  f.seconds = seconds;
  return f;
}

void CloudCompareMethods(const PointCloud& points, const fs::path& folder, const Epoch& before,
                         const fs::path& design_ply, const std::vector<int>& label,
                         const std::vector<Change>& changes, ChangeFigures& figures) {
  perception::WriteCloud(folder / "compared.ply", points);
  perception::WriteCloud(folder / "reference.ply", before.map.cloud);
  const double target = FalseShare(figures.methods.at("uwscan"));
  // Cloud-to-cloud with its best local model for a smooth surface: a least-squares plane through
  // the 12 nearest. It saves both clouds, so it is given two names.
  figures.methods["cloudcompare_c2c"] =
      CloudCompareMethod("c2c",
                         {"-O", (folder / "reference.ply").string(), "-C2C_DIST", "-MODEL", "LS",
                          "KNN", "12", "-SAVE_CLOUDS", "FILE",
                          (folder / "c2c.asc").string() + " " + (folder / "c2c_ref.asc").string()},
                         false, points, folder, label, changes, target);
  figures.methods["cloudcompare_c2m"] =
      CloudCompareMethod("c2m",
                         {"-O", design_ply.string(), "-C2M_DIST", "-SAVE_CLOUDS", "FILE",
                          (folder / "c2m.asc").string()},
                         true, points, folder, label, changes, target);
  figures.cloudcompare_ran = true;
}

// uwscan's comparison of the second survey against a reference, judged.
MethodFigures UwscanMethod(const Epoch& after, const mapping::Survey& reference,
                           const mapping::CompareOptions& options,
                           const std::vector<Change>& changes) {
  const mapping::SurveyComparison c = mapping::CompareSurveys(after.map, reference, options);
  MethodFigures f = Judge(c.deviations, TruthLabels(c.deviations, changes), changes, true);
  f.seconds = c.seconds;
  return f;
}

mapping::Survey DesignSurvey(const scanner::sim::Scene& scene, const fs::path& ply) {
  scanner::WriteMeshPly(scanner::sim::SceneMesh(scene), ply);
  return mapping::ReadSurvey(ply);
}

}  // namespace

void ChangeBenchOptions::Check() const {
  const OptionChecks check("ChangeBenchOptions");
  check.Require(!before_scene.empty(), "before_scene", "a scene file", "''");
  check.Require(!after_scene.empty(), "after_scene", "a scene file", "''");
  check.GreaterThan("threads", threads, 0);
}

ChangeFigures RunChangeBench(const ChangeBenchOptions& options, const Progress& progress) {
  options.Check();
  omp_set_num_threads(options.threads);
  ScratchFolder scratch("bench-change");
  ChangeFigures figures;
  const Epoch before =
      SurveyEpoch(options.before_scene, scratch.path(), options, progress, figures);
  const Epoch after = SurveyEpoch(options.after_scene, scratch.path(), options, progress, figures);
  figures.map_rms_m =
      std::sqrt(0.5 * (before.map_rms_m * before.map_rms_m + after.map_rms_m * after.map_rms_m));
  const std::vector<Change> changes = ChangesBetween(before.scene, after.scene);
  if (progress) progress("compare", 0.0);
  // As `uwscan compare` does with two map reports.
  mapping::CompareOptions tiles;
  figures.methods["uwscan"] = UwscanMethod(after, before.map, tiles, changes);
  // The same with each pose's marginal covariance alone (the relative placement unknown).
  mapping::CompareOptions marginal = tiles;
  marginal.joint_pose_uncertainty = false;
  figures.methods["uwscan_marginal_covariances"] =
      UwscanMethod(after, before.map, marginal, changes);
  mapping::CompareOptions whole = tiles;
  whole.alignment.tile_m = 0.0;
  figures.methods["uwscan_pose_covariances"] = UwscanMethod(after, before.map, whole, changes);
  const fs::path design_ply = scratch.path() / "design_before.ply";
  figures.methods["uwscan_design"] =
      UwscanMethod(after, DesignSurvey(before.scene, design_ply), tiles, changes);

  const PointCloud points = perception::VoxelDownsample(after.map.cloud, {.leaf_m = kSpacing_m});
  std::vector<CoreDeviation> judged = AsPoints(points, std::vector<double>(points.size(), 0.0));
  const std::vector<int> label = TruthLabels(judged, changes);
  const auto start = Clock::now();
  const std::vector<double> nearest = NearestDistances(points, before.map.cloud);
  const double nearest_seconds = SecondsSince(start);
  figures.methods["nearest"] = JudgeAtEqualFalseArea(
      AsPoints(points, nearest), label, changes, false, FalseShare(figures.methods.at("uwscan")));
  figures.methods["nearest"].seconds = nearest_seconds;
  if (options.run_cloudcompare && CloudCompareInstalled()) {
    if (progress) progress("cloudcompare", 0.0);
    CloudCompareMethods(points, scratch.path(), before, design_ply, label, changes, figures);
  }
  if (progress) progress("compare", 1.0);
  return figures;
}

}  // namespace uwscan::bench
