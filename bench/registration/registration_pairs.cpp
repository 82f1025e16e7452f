#include "bench/registration/registration_pairs.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "perception/cloud/cloud_io.hpp"
#include "perception/cloud/cloud_neighbors.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/common/random_draws.hpp"
#include "scanner/common/triangle_mesh.hpp"

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

void AddMeshPairs(const std::filesystem::path& cache, const RegistrationPairOptions& o,
                  std::mt19937_64& rng, std::vector<RegistrationPair>* pairs) {
  for (const char* name : kMeshes) {
    scanner::TriangleMesh mesh = scanner::LoadMesh(cache / "meshes" / (std::string(name) + ".off"));
    const double scale = o.mesh_size_m / mesh.BoundingBoxDiagonal();
    for (Eigen::Vector3d& v : mesh.vertices) v *= scale;
    // Each view gets its own sampling of the surface, as two scans would.
    const scanner::SurfaceSamples surface = scanner::SampleSurface(mesh, o.mesh_samples, rng());
    const scanner::SurfaceSamples other = scanner::SampleSurface(mesh, o.mesh_samples, rng());
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p : surface.points) centroid += p;
    centroid /= static_cast<double>(surface.points.size());
    std::normal_distribution<double> gauss(0.0, 1.0);
    for (int k = 0; k < o.pairs_per_mesh; ++k) {
      RegistrationPair pair;
      pair.name = std::string(name) + "#" + std::to_string(k);
      // Viewpoints from which an open mesh shows (almost) no front faces are drawn again.
      std::vector<Eigen::Vector3d> target, source;
      const double distance = 3.0 * o.mesh_size_m;
      for (int attempt = 0; attempt < 50 && (target.size() < 500 || source.size() < 500);
           ++attempt) {
        const Eigen::Vector3d a = DrawVector3LastFirst(gauss, rng).normalized();
        const Eigen::Vector3d b = Eigen::AngleAxisd(o.view_separation_rad, a.unitOrthogonal()) * a;
        pair.target_viewpoint = centroid + distance * a;
        pair.source_viewpoint = centroid + distance * b;
        target = PartialView(surface, pair.target_viewpoint, o.noise_sigma_m, rng);
        source = PartialView(other, pair.source_viewpoint, o.noise_sigma_m, rng);
      }
      if (target.size() < 500 || source.size() < 500) {
        throw Error(std::string("registration pairs: no usable views of mesh '") + name + "'");
      }
      const Eigen::Isometry3d T_source_target = RandomMotion(rng, o.mesh_size_m);
      for (Eigen::Vector3d& p : source) p = T_source_target * p;
      pair.source_viewpoint = T_source_target * pair.source_viewpoint;
      pair.target = perception::MakeCloud(target);
      pair.source = perception::MakeCloud(source);
      std::vector<Eigen::Vector3d> surface_in_source;
      surface_in_source.reserve(other.points.size());
      for (const Eigen::Vector3d& p : other.points)
        surface_in_source.push_back(T_source_target * p);
      pair.surface = perception::MakeCloud(surface_in_source);
      pair.T_target_source_true = T_source_target.inverse();
      pair.object_size_m = perception::BoundingBoxDiagonal(pair.target);
      pairs->push_back(std::move(pair));
    }
  }
}

void AddScanPairs(const std::filesystem::path& cache, std::mt19937_64& rng,
                  std::vector<RegistrationPair>* pairs) {
  struct Scan {
    const char* file;
    double keep;  // fraction of the scan's points in each view
  };
  for (const Scan scan : {Scan{"bun0", 0.7}, Scan{"table_scene_lms400", 0.25}}) {
    const std::vector<Eigen::Vector3d> points =
        Absolute(perception::ReadCloud(cache / "scans" / (std::string(scan.file) + ".pcd")));
    const perception::PointCloud reference = perception::MakeCloud(points);
    const double size = perception::BoundingBoxDiagonal(reference);
    RegistrationPair pair;
    pair.name = scan.file;
    pair.target = perception::MakeCloud(
        Resampled(points, scan.keep, 0.0, Eigen::Isometry3d::Identity(), rng));
    const Eigen::Isometry3d T_source_target = RandomMotion(rng, size);
    pair.source =
        perception::MakeCloud(Resampled(points, scan.keep, 1e-3 * size, T_source_target, rng));
    pair.source_viewpoint = T_source_target * Eigen::Vector3d::Zero();  // the scanner's origin
    std::vector<Eigen::Vector3d>
        surface_in_source;  // every point, no draw: the pairs stay as they were
    surface_in_source.reserve(points.size());
    for (const Eigen::Vector3d& p : points) surface_in_source.push_back(T_source_target * p);
    pair.surface = perception::MakeCloud(surface_in_source);
    pair.T_target_source_true = T_source_target.inverse();
    pair.object_size_m = size;
    pairs->push_back(std::move(pair));
  }
}

}  // namespace

void RegistrationPairOptions::Check() const {
  const OptionChecks check("RegistrationPairOptions");
  check.AtLeast("mesh_samples", mesh_samples, 1000);
  check.GreaterThan("mesh_size_m", mesh_size_m, 0.0, "m");
  check.AtLeast("noise_sigma_m", noise_sigma_m, 0.0, "m");
  check.AtLeast("pairs_per_mesh", pairs_per_mesh, 1);
}

std::vector<RegistrationPair> MakeRegistrationPairs(const std::filesystem::path& data_cache,
                                                    const RegistrationPairOptions& options) {
  options.Check();
  std::mt19937_64 rng(options.seed);
  std::vector<RegistrationPair> pairs;
  AddMeshPairs(data_cache, options, rng, &pairs);
  if (options.real_scans) AddScanPairs(data_cache, rng, &pairs);
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
