#include "bench/registration/registration_pairs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>

#include "perception/cloud/cloud_io.hpp"
#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/cloud/cloud_scale.hpp"
#include "perception/registration/cloud_fit.hpp"
#include "perception/registration/registration_pipeline.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/common/random_draws.hpp"
#include "scanner/common/triangle_mesh.hpp"
#include "scanner/lasers/scanner_file.hpp"
#include "scanner/sim/virtual_scanner.hpp"

namespace uwscan::bench {
namespace {

constexpr const char* kMeshes[] = {"anchor",  "cylinder",     "joint",         "rotor",  "spool",
                                   "turbine", "pinion_small", "fandisk_large", "bunny00"};

Eigen::Isometry3d RandomMotion(std::mt19937_64& rng, double max_translation_m) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Vector3d axis = DrawVector3LastFirst(gauss, rng).normalized();
  const double angle = unit(rng) * 3.14159265358979323846;
  Eigen::Vector3d t = DrawVector3LastFirst(gauss, rng);
  t *= unit(rng) * max_translation_m / t.norm();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
  T.translation() = t;
  return T;
}

// The points of a sampled surface whose normals face the viewpoint, with noise.
std::vector<Eigen::Vector3d> PartialView(const scanner::SurfaceSamples& surface,
                                         const Eigen::Vector3d& viewpoint, double sigma_m,
                                         std::mt19937_64& rng) {
  std::normal_distribution<double> noise(0.0, sigma_m);
  std::vector<Eigen::Vector3d> view;
  for (size_t i = 0; i < surface.points.size(); ++i) {
    if (surface.normals[i].dot(viewpoint - surface.points[i]) <= 0.0) continue;
    view.push_back(surface.points[i] + DrawVector3LastFirst(noise, rng));
  }
  return view;
}

std::vector<Eigen::Vector3d> Absolute(const perception::PointCloud& cloud) {
  std::vector<Eigen::Vector3d> points(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) points[i] = cloud.Point(i);
  return points;
}

// A random fraction of the points, with noise, moved by T.
std::vector<Eigen::Vector3d> Resampled(const std::vector<Eigen::Vector3d>& points, double keep,
                                       double sigma_m, const Eigen::Isometry3d& T,
                                       std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, sigma_m);
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector3d& p : points) {
    if (unit(rng) < keep) out.push_back(T * (p + DrawVector3LastFirst(noise, rng)));
  }
  return out;
}

scanner::TriangleMesh LoadScaledMesh(const std::filesystem::path& cache, const std::string& name,
                                     double size_m) {
  scanner::TriangleMesh mesh = scanner::LoadMesh(cache / "meshes" / (name + ".off"));
  const double scale = size_m / mesh.BoundingBoxDiagonal();
  for (Eigen::Vector3d& v : mesh.vertices) v *= scale;
  return mesh;
}

// Two independent samplings of one mesh's surface, as two scans would give.
struct TwoSamplings {
  scanner::SurfaceSamples surface, other;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
};

TwoSamplings SampleTwice(const scanner::TriangleMesh& mesh, int samples, std::mt19937_64& rng) {
  TwoSamplings s{scanner::SampleSurface(mesh, samples, rng()),
                 scanner::SampleSurface(mesh, samples, rng())};
  for (const Eigen::Vector3d& p : s.surface.points) s.centroid += p;
  s.centroid /= static_cast<double>(s.surface.points.size());
  return s;
}

// Two partial views of the object, from viewpoints `separation_rad` apart at three object sizes
// from its centroid: the target from one sampling, the source from the other. Viewpoints from
// which an open mesh shows (almost) no front faces are drawn again.
struct TwoViews {
  std::vector<Eigen::Vector3d> target, source;
  Eigen::Vector3d target_viewpoint, source_viewpoint;
};

// `gauss` (a unit normal) is the caller's, kept across a mesh's pairs: a normal distribution
// holds a draw back between calls, and the main pairs' views must stay as published.
TwoViews CutTwoViews(const TwoSamplings& s, const std::string& name, double separation_rad,
                     const RegistrationPairOptions& o, std::normal_distribution<double>& gauss,
                     std::mt19937_64& rng) {
  TwoViews v;
  const double distance = 3.0 * o.mesh_size_m;
  for (int attempt = 0; attempt < 50 && (v.target.size() < 500 || v.source.size() < 500);
       ++attempt) {
    const Eigen::Vector3d a = DrawVector3LastFirst(gauss, rng).normalized();
    const Eigen::Vector3d b = Eigen::AngleAxisd(separation_rad, a.unitOrthogonal()) * a;
    v.target_viewpoint = s.centroid + distance * a;
    v.source_viewpoint = s.centroid + distance * b;
    v.target = PartialView(s.surface, v.target_viewpoint, o.noise_sigma_m, rng);
    v.source = PartialView(s.other, v.source_viewpoint, o.noise_sigma_m, rng);
  }
  if (v.target.size() < 500 || v.source.size() < 500) {
    throw Error("registration pairs: no usable views of mesh '" + name + "'");
  }
  return v;
}

// The pair of the two views with the source moved by a random rigid motion; `surface` is the
// object's whole surface in the object's frame.
RegistrationPair MovedPair(const std::string& name, TwoViews views,
                           const std::vector<Eigen::Vector3d>& surface, double max_translation_m,
                           std::mt19937_64& rng) {
  RegistrationPair pair;
  pair.name = name;
  const Eigen::Isometry3d T_source_target = RandomMotion(rng, max_translation_m);
  for (Eigen::Vector3d& p : views.source) p = T_source_target * p;
  pair.source_viewpoint = T_source_target * views.source_viewpoint;
  pair.target_viewpoint = views.target_viewpoint;
  pair.target = perception::MakeCloud(views.target);
  pair.source = perception::MakeCloud(views.source);
  std::vector<Eigen::Vector3d> surface_in_source;
  surface_in_source.reserve(surface.size());
  for (const Eigen::Vector3d& p : surface) surface_in_source.push_back(T_source_target * p);
  pair.surface = perception::MakeCloud(surface_in_source);
  pair.T_target_source_true = T_source_target.inverse();
  pair.object_size_m = perception::BoundingBoxDiagonal(pair.target);
  return pair;
}

void AddMeshPairs(const std::filesystem::path& cache, const RegistrationPairOptions& o,
                  std::mt19937_64& rng, std::vector<RegistrationPair>* pairs) {
  for (const char* name : kMeshes) {
    const TwoSamplings s =
        SampleTwice(LoadScaledMesh(cache, name, o.mesh_size_m), o.mesh_samples, rng);
    std::normal_distribution<double> gauss(0.0, 1.0);
    for (int k = 0; k < o.pairs_per_mesh; ++k) {
      TwoViews views = CutTwoViews(s, name, o.view_separation_rad, o, gauss, rng);
      pairs->push_back(MovedPair(std::string(name) + "#" + std::to_string(k), std::move(views),
                                 s.other.points, o.mesh_size_m, rng));
    }
  }
}

// A random half of the points: a sparser scan of the same surface.
std::vector<Eigen::Vector3d> Thinned(const std::vector<Eigen::Vector3d>& points,
                                     std::mt19937_64& rng) {
  std::bernoulli_distribution keep(0.5);
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector3d& p : points) {
    if (keep(rng)) out.push_back(p);
  }
  return out;
}

// The points with `fraction` of their number added, uniformly within their bounding box
// (grown by a tenth on each side): spray, fish, a stray reflection.
std::vector<Eigen::Vector3d> WithOutliers(std::vector<Eigen::Vector3d> points, double fraction,
                                          std::mt19937_64& rng) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& p : points) box.extend(p);
  const Eigen::Vector3d margin = 0.1 * box.sizes();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto count = static_cast<std::size_t>(fraction * static_cast<double>(points.size()));
  for (std::size_t i = 0; i < count; ++i) {
    const Eigen::Vector3d u = DrawVector3(unit, rng);
    points.push_back(box.min() - margin + u.cwiseProduct(box.sizes() + 2.0 * margin));
  }
  return points;
}

// Per mesh, views further apart than the main pairs' (less overlap): at 1.2 rad with the source
// half as dense, at 1.8 rad with outliers in the source.
void AddHardMeshPairs(const std::filesystem::path& cache, const RegistrationPairOptions& o,
                      std::mt19937_64& rng, std::vector<RegistrationPair>* pairs) {
  for (const char* name : kMeshes) {
    const TwoSamplings s =
        SampleTwice(LoadScaledMesh(cache, name, o.mesh_size_m), o.mesh_samples, rng);
    std::normal_distribution<double> gauss(0.0, 1.0);
    TwoViews sparse = CutTwoViews(s, name, 1.2, o, gauss, rng);
    sparse.source = Thinned(sparse.source, rng);
    pairs->push_back(MovedPair(std::string(name) + " sparse 1.2 rad", std::move(sparse),
                               s.other.points, o.mesh_size_m, rng));
    TwoViews outliers = CutTwoViews(s, name, 1.8, o, gauss, rng);
    const std::size_t surface_points = outliers.source.size();
    outliers.source = WithOutliers(std::move(outliers.source), o.outlier_fraction, rng);
    RegistrationPair pair = MovedPair(std::string(name) + " outliers 1.8 rad", std::move(outliers),
                                      s.other.points, o.mesh_size_m, rng);
    pair.source_outliers = pair.source.size() - surface_points;
    pairs->push_back(std::move(pair));
  }
}

// Views of two different objects: no answer exists.
void AddUnrelatedPairs(const std::filesystem::path& cache, const RegistrationPairOptions& o,
                       std::mt19937_64& rng, std::vector<RegistrationPair>* pairs) {
  const std::pair<const char*, const char*> kUnrelated[] = {{"anchor", "joint"},
                                                            {"rotor", "turbine"},
                                                            {"fandisk_large", "bunny00"},
                                                            {"spool", "pinion_small"}};
  for (const auto& [target_name, source_name] : kUnrelated) {
    const TwoSamplings target =
        SampleTwice(LoadScaledMesh(cache, target_name, o.mesh_size_m), o.mesh_samples, rng);
    const TwoSamplings source =
        SampleTwice(LoadScaledMesh(cache, source_name, o.mesh_size_m), o.mesh_samples, rng);
    std::normal_distribution<double> gauss(0.0, 1.0);
    TwoViews views = CutTwoViews(target, target_name, 0.6, o, gauss, rng);
    const TwoViews source_views = CutTwoViews(source, source_name, 0.6, o, gauss, rng);
    views.source = source_views.source;
    views.source_viewpoint = source_views.source_viewpoint;
    RegistrationPair pair = MovedPair(std::string(source_name) + " onto " + target_name,
                                      std::move(views), source.other.points, o.mesh_size_m, rng);
    pair.overlapping = false;
    pairs->push_back(std::move(pair));
  }
}

// Two sweeps of the virtual scanner, each in its own camera frame.
struct TwoSweeps {
  scanner::sim::VirtualScan target, source;
  Eigen::Isometry3d T_W_target, T_W_source;
  double separation_rad = 0.0;
};

// Views drawn `separation` apart (0.5-1.4 rad) at stand-offs of 0.7-1.3 m each, drawn again while
// either sweep holds fewer than 500 points.
TwoSweeps SweepTwice(const scanner::sim::VirtualScanner& scanner,
                     const scanner::sim::SceneObject& object, std::mt19937_64& rng) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& v : object.mesh.vertices) box.extend(v);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> standoff_m(0.7, 1.3), separation_rad(0.5, 1.4);
  TwoSweeps s;
  for (int attempt = 0; attempt < 50; ++attempt) {
    const Eigen::Vector3d a = DrawVector3LastFirst(gauss, rng).normalized();
    s.separation_rad = separation_rad(rng);
    const Eigen::Vector3d b = Eigen::AngleAxisd(s.separation_rad, a.unitOrthogonal()) * a;
    s.T_W_target = scanner::sim::ViewFrom(box.center(), a, standoff_m(rng));
    s.T_W_source = scanner::sim::ViewFrom(box.center(), b, standoff_m(rng));
    s.target = scanner.Scan({object}, s.T_W_target, rng());
    s.source = scanner.Scan({object}, s.T_W_source, rng());
    if (s.target.points_C.size() >= 500 && s.source.points_C.size() >= 500) return s;
  }
  throw Error("registration pairs: the virtual scanner sees too little of mesh '" + object.name +
              "'");
}

// The two sweeps as a pair, the source moved by a random rigid motion on top of its camera
// frame; `surface` (object frame = world) is the whole object's.
RegistrationPair SweepPair(const std::string& name, const TwoSweeps& s,
                           const std::vector<Eigen::Vector3d>& surface, double max_translation_m,
                           std::mt19937_64& rng) {
  RegistrationPair pair;
  pair.name = name;
  const Eigen::Isometry3d T_moved_C = RandomMotion(rng, max_translation_m);
  std::vector<Eigen::Vector3d> source = s.source.points_C;
  for (Eigen::Vector3d& p : source) p = T_moved_C * p;
  const Eigen::Isometry3d T_moved_W = T_moved_C * s.T_W_source.inverse();
  std::vector<Eigen::Vector3d> surface_in_source;
  surface_in_source.reserve(surface.size());
  for (const Eigen::Vector3d& p : surface) surface_in_source.push_back(T_moved_W * p);
  pair.target = perception::MakeCloud(s.target.points_C);
  pair.source = perception::MakeCloud(source);
  pair.surface = perception::MakeCloud(surface_in_source);
  pair.source_viewpoint = T_moved_C.translation();  // the camera's centre
  pair.target_viewpoint = Eigen::Vector3d::Zero();
  pair.T_target_source_true = s.T_W_target.inverse() * T_moved_W.inverse();
  pair.object_size_m = perception::BoundingBoxDiagonal(pair.target);
  return pair;
}

// Per mesh, two sweeps of the virtual scanner (the default galvanometer scanner under water:
// refraction at both viewports, occlusion, 0.1 px of noise on the exact peaks, no rendered
// frames): a real sweep's density, along its lines and falling with range and incidence, and its
// noise along the camera's rays.
void AddSweepPairs(const std::filesystem::path& cache, const RegistrationPairOptions& o,
                   std::mt19937_64& rng, std::vector<RegistrationPair>* pairs) {
  scanner::sim::VirtualScannerOptions scan_options;
  scan_options.pattern.kind = scanner::ScannerKind::kGalvo;
  scan_options.table_cache = o.table_cache;
  const scanner::sim::VirtualScanner scanner(scanner::DefaultScanner(scanner::ScannerKind::kGalvo),
                                             scan_options);
  for (const char* name : kMeshes) {
    scanner::sim::SceneObject object;
    object.name = name;
    object.shape = scanner::sim::ObjectShape::kMesh;
    object.mesh = LoadScaledMesh(cache, name, o.mesh_size_m);
    const TwoSweeps sweeps = SweepTwice(scanner, object, rng);
    const std::vector<Eigen::Vector3d> surface =
        scanner::SampleSurface(object.mesh, o.mesh_samples, rng()).points;
    char label[64];
    std::snprintf(label, sizeof label, " sweeps %.1f rad", sweeps.separation_rad);
    pairs->push_back(SweepPair(name + std::string(label), sweeps, surface, o.mesh_size_m, rng));
  }
}

// A pair from a real scan: the target and the source drawn from `target_points` and
// `source_points` (each point kept with probability `keep`), the source with noise of a
// thousandth of the scan's size and moved by a random rigid motion; `points` is the whole scan.
RegistrationPair ScanPair(const std::string& name, const std::vector<Eigen::Vector3d>& points,
                          const std::vector<Eigen::Vector3d>& target_points,
                          const std::vector<Eigen::Vector3d>& source_points, double keep,
                          std::mt19937_64& rng) {
  const double size = perception::BoundingBoxDiagonal(perception::MakeCloud(points));
  RegistrationPair pair;
  pair.name = name;
  pair.target = perception::MakeCloud(
      Resampled(target_points, keep, 0.0, Eigen::Isometry3d::Identity(), rng));
  const Eigen::Isometry3d T_source_target = RandomMotion(rng, size);
  pair.source =
      perception::MakeCloud(Resampled(source_points, keep, 1e-3 * size, T_source_target, rng));
  pair.source_viewpoint = T_source_target * Eigen::Vector3d::Zero();  // the scanner's origin
  std::vector<Eigen::Vector3d> surface_in_source;                     // every point, no draw
  surface_in_source.reserve(points.size());
  for (const Eigen::Vector3d& p : points) surface_in_source.push_back(T_source_target * p);
  pair.surface = perception::MakeCloud(surface_in_source);
  pair.T_target_source_true = T_source_target.inverse();
  pair.object_size_m = size;
  pair.voxel_m =
      perception::RegistrationPipelineOptions::ForClouds(pair.source, pair.target).voxel_m;
  return pair;
}

struct Scan {
  const char* file;
  double keep;  // fraction of the scan's points in each view
};
constexpr Scan kScans[] = {{"bun0", 0.7}, {"table_scene_lms400", 0.25}};

std::vector<Eigen::Vector3d> ScanPoints(const std::filesystem::path& cache, const Scan& scan) {
  return Absolute(perception::ReadCloud(cache / "scans" / (std::string(scan.file) + ".pcd")));
}

void AddScanPairs(const std::filesystem::path& cache, std::mt19937_64& rng,
                  std::vector<RegistrationPair>* pairs) {
  for (const Scan& scan : kScans) {
    const std::vector<Eigen::Vector3d> points = ScanPoints(cache, scan);
    pairs->push_back(ScanPair(scan.file, points, points, points, scan.keep, rng));
  }
}

// The points whose x lies between the two quantiles of the scan's x.
std::vector<Eigen::Vector3d> CutAlongX(const std::vector<Eigen::Vector3d>& points, double from,
                                       double to) {
  std::vector<double> x(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) x[i] = points[i].x();
  std::sort(x.begin(), x.end());
  const auto quantile = [&x](double q) {
    return x[static_cast<std::size_t>(q * static_cast<double>(x.size() - 1))];
  };
  const double low = quantile(from), high = quantile(to);
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector3d& p : points) {
    if (p.x() >= low && p.x() <= high) out.push_back(p);
  }
  return out;
}

// Each real scan cut across x into two parts, the source moved and noisy as in AddScanPairs:
// overlapping (the first 65 % and the last 65 %: about half of each part shared) and disjoint
// (the first 45 % and the last 45 %: a tenth of the scan between them, nothing shared).
void AddScanCuts(const std::filesystem::path& cache, std::mt19937_64& rng,
                 std::vector<RegistrationPair>* pairs) {
  struct Cut {
    const char* name;
    double source_to, target_from;
    bool overlapping;
  };
  for (const Scan& scan : kScans) {
    const std::vector<Eigen::Vector3d> points = ScanPoints(cache, scan);
    for (const Cut cut : {Cut{"cut in two, overlapping", 0.65, 0.35, true},
                          Cut{"cut in two, disjoint", 0.45, 0.55, false}}) {
      RegistrationPair pair = ScanPair(std::string(scan.file) + " " + cut.name, points,
                                       CutAlongX(points, cut.target_from, 1.0),
                                       CutAlongX(points, 0.0, cut.source_to), scan.keep, rng);
      pair.overlapping = cut.overlapping;
      pairs->push_back(std::move(pair));
    }
  }
}

}  // namespace

double MeasureOverlap(const RegistrationPair& pair, double radius_m) {
  std::vector<std::size_t> on_surface(pair.source.size() - pair.source_outliers);
  std::iota(on_surface.begin(), on_surface.end(), std::size_t{0});
  const perception::PointCloud source = perception::Subset(pair.source, on_surface);
  const Eigen::Isometry3d& T = pair.T_target_source_true;
  return std::min(perception::FitOnTarget(source, pair.target, T, radius_m).fitness,
                  perception::FitOnTarget(pair.target, source, T.inverse(), radius_m).fitness);
}

void RegistrationPairOptions::Check() const {
  const OptionChecks check("RegistrationPairOptions");
  check.AtLeast("mesh_samples", mesh_samples, 1000);
  check.GreaterThan("mesh_size_m", mesh_size_m, 0.0, "m");
  check.AtLeast("noise_sigma_m", noise_sigma_m, 0.0, "m");
  check.AtLeast("pairs_per_mesh", pairs_per_mesh, 1);
  check.InRange("outlier_fraction", outlier_fraction, 0.0, 1.0, Interval::kOpenHigh);
}

std::vector<RegistrationPair> MakeRegistrationPairs(const std::filesystem::path& data_cache,
                                                    const RegistrationPairOptions& options) {
  options.Check();
  std::mt19937_64 rng(options.seed);
  std::vector<RegistrationPair> pairs;
  AddMeshPairs(data_cache, options, rng, &pairs);
  if (options.real_scans) AddScanPairs(data_cache, rng, &pairs);
  if (options.hard_pairs) {
    // Each group draws from its own stream: leaving one out (--no-real-scans) leaves the
    // others as they are.
    std::mt19937_64 hard_rng(options.seed * 7919 + 1), cut_rng(options.seed * 7919 + 2),
        unrelated_rng(options.seed * 7919 + 3), sweep_rng(options.seed * 7919 + 4);
    AddHardMeshPairs(data_cache, options, hard_rng, &pairs);
    if (options.real_scans) AddScanCuts(data_cache, cut_rng, &pairs);
    AddUnrelatedPairs(data_cache, options, unrelated_rng, &pairs);
    AddSweepPairs(data_cache, options, sweep_rng, &pairs);
  }
  for (RegistrationPair& pair : pairs) {
    // Within 1 % of the object's size (the success test's tolerance), but never less than a few
    // sampling steps of the sparser cloud, which would make a sparse view look disjoint.
    const double spacing_m = std::max(perception::MedianPointSpacing(pair.source),
                                      perception::MedianPointSpacing(pair.target));
    const double radius_m = std::max(0.01 * pair.object_size_m, 2.5 * spacing_m);
    if (pair.overlapping) pair.overlap = MeasureOverlap(pair, radius_m);
  }
  return pairs;
}

PoseError ComparePoses(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth,
                       const Eigen::Vector3d& at_point) {
  const Eigen::Isometry3d delta = truth.inverse() * estimate;
  const double cos_angle = std::clamp((delta.linear().trace() - 1.0) / 2.0, -1.0, 1.0);
  return PoseError{std::acos(cos_angle), (estimate * at_point - truth * at_point).norm()};
}

double SymmetricSurfaceError(const perception::PointCloud& source,
                             const perception::PointCloud& surface,
                             const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth,
                             std::size_t max_points) {
  if (source.empty() || surface.empty())
    throw Error("SymmetricSurfaceError: empty source or surface");
  // Coordinates relative to where the truth puts the source's origin keep the floats small.
  const Eigen::Vector3d centre = truth * source.origin;
  std::vector<Eigen::Vector3f> true_points;
  true_points.reserve(surface.size());
  for (std::size_t i = 0; i < surface.size(); ++i)
    true_points.push_back((truth * surface.Point(i) - centre).cast<float>());
  const perception::KnnIndex index(true_points);
  const std::size_t stride = std::max<std::size_t>(
      1, (source.size() + max_points - 1) / std::max<std::size_t>(1, max_points));
  std::vector<std::uint32_t> nearest;
  std::vector<float> squared_m2;
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < source.size(); i += stride, ++n) {
    index.Query((estimate * source.Point(i) - centre).cast<float>(), 1, nearest, squared_m2);
    sum += std::sqrt(static_cast<double>(squared_m2.front()));
  }
  return sum / static_cast<double>(n);
}

}  // namespace uwscan::bench
