#include "perception/recognition/object_database_builder.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>

#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/preprocessing/voxel_filter.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"
#include "scanner/sim/ray_caster.hpp"

namespace uwscan::perception {
namespace {

constexpr int kMinViewPoints = 50;
constexpr std::size_t kMinModelPoints = 50;  // visible model samples an object needs

std::uint64_t Mix(std::uint64_t a, std::uint64_t b) {
  std::uint64_t z = a * 0x9E3779B97F4A7C15ull + b + 0x632BE59BD9B4E019ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Surface samples with the mesh's outward normals, seen from outside, one per voxel and facing: in
// each voxel, for each of the six directions a normal can mostly point along, the sample nearest
// the centroid of those samples. A real sample stays on the surface, where a centroid would sit
// between the outer and inner walls of a thin pipe (5 mm apart, one voxel) and pull every ICP
// on the model a few millimetres inwards; splitting by facing keeps both walls.
PointCloud ModelCloud(const std::string& id, const scanner::TriangleMesh& mesh, double voxel_m,
                      std::uint64_t seed) {
  double area = 0.0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[static_cast<std::size_t>(t[0])];
    area += 0.5 * (mesh.vertices[static_cast<std::size_t>(t[1])] - a)
                      .cross(mesh.vertices[static_cast<std::size_t>(t[2])] - a)
                      .norm();
  }
  const int count =
      static_cast<int>(std::clamp(16.0 * area / (voxel_m * voxel_m), 2000.0, 400000.0));
  const scanner::SurfaceSamples samples = scanner::SampleSurface(mesh, count, seed);
  // Key: voxel indices and facing (0-5); ordered, so the cloud does not depend on hashing.
  std::map<std::array<long, 4>, std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < samples.points.size(); ++i) {
    const Eigen::Vector3d& p = samples.points[i];
    const Eigen::Vector3d& n = samples.normals[i];
    int axis = 0;
    n.cwiseAbs().maxCoeff(&axis);
    const long facing = 2 * axis + (n[axis] < 0.0 ? 1 : 0);
    groups[{std::lround(std::floor(p.x() / voxel_m)), std::lround(std::floor(p.y() / voxel_m)),
            std::lround(std::floor(p.z() / voxel_m)), facing}]
        .push_back(i);
  }
  // Only surface a sensor outside can see: a sample is kept when a straight line leaves it to
  // beyond the object in one of 64 directions in front of it (bores deep inside a pipe, and a
  // tee's branch end buried in its run, are not).
  scanner::sim::SceneObject object;
  object.shape = scanner::sim::ObjectShape::kMesh;
  object.mesh = mesh;
  const scanner::sim::RayCaster caster({object});
  const std::vector<Eigen::Vector3d> directions = scanner::sim::SphereDirections(64);
  const double reach = 2.0 * mesh.BoundingBoxDiagonal();
  auto visible = [&](std::size_t i) {
    for (const Eigen::Vector3d& d : directions) {
      if (d.dot(samples.normals[i]) < 0.05) continue;
      if (!caster.Blocked(samples.points[i], samples.points[i] + reach * d, 1e-6)) return true;
    }
    return false;
  };
  std::vector<Eigen::Vector3d> points, normals;
  for (const auto& [key, members] : groups) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (std::size_t i : members) centroid += samples.points[i];
    centroid /= static_cast<double>(members.size());
    // The visible sample nearest the centroid, among the four nearest (a group hidden as a
    // whole, a bore's, is dropped without casting for every sample).
    std::vector<std::size_t> order = members;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return (samples.points[a] - centroid).squaredNorm() <
             (samples.points[b] - centroid).squaredNorm();
    });
    order.resize(std::min<std::size_t>(order.size(), 4));
    const auto seen = std::find_if(order.begin(), order.end(), visible);
    if (seen == order.end()) continue;
    points.push_back(samples.points[*seen]);
    normals.push_back(samples.normals[*seen]);
  }
  if (points.size() < kMinModelPoints) {
    throw Error("build-db: only " + std::to_string(points.size()) + " surface samples of '" + id +
                "' are visible from outside (is the mesh closed and wound counter-clockwise seen "
                "from outside?)");
  }
  PointCloud model = MakeCloud(points);
  for (const Eigen::Vector3d& n : normals) model.normals.push_back(n.cast<float>());
  return model;
}

}  // namespace

void DatabaseBuildOptions::Check() const {
  const OptionChecks check("DatabaseBuildOptions");
  check.AtLeast("views", views, 1);
  check.Require(!standoffs_m.empty(), "standoffs_m", "at least one stand-off", "none");
  for (std::size_t i = 0; i < standoffs_m.size(); ++i) {
    if (!(std::isfinite(standoffs_m[i]) && standoffs_m[i] > 0.0)) {
      check.Fail("standoffs_m[" + std::to_string(i) + "]", "a finite value > 0 m",
                 OptionValueText(standoffs_m[i]));
    }
  }
  check.GreaterThan("parameters.voxel_m", parameters.voxel_m, 0.0, "m");
  check.Require(parameters.normal_radius_m > parameters.voxel_m, "parameters.normal_radius_m",
                "> parameters.voxel_m (" + OptionValueText(parameters.voxel_m) + " m)",
                parameters.normal_radius_m);
  check.Require(
      parameters.feature_radius_m > parameters.normal_radius_m, "parameters.feature_radius_m",
      "> parameters.normal_radius_m (" + OptionValueText(parameters.normal_radius_m) + " m)",
      parameters.feature_radius_m);
  check.AtLeast("threads", threads, 0);
}

EsfResult VoxelisedEsf(const PointCloud& cloud, double voxel_m, std::uint64_t seed, int threads) {
  EsfOptions options;
  options.seed = seed;
  options.threads = threads;
  return ComputeEsf(VoxelDownsample(cloud, VoxelFilterOptions{voxel_m}), options);
}

Eigen::Isometry3d ViewPose(int index, int count, const Eigen::Vector3d& centre_O,
                           double standoff_m) {
  return scanner::sim::ViewFrom(
      centre_O, scanner::sim::SphereDirections(count)[static_cast<std::size_t>(index)], standoff_m);
}

ObjectDatabase BuildObjectDatabase(std::span<const ObjectSource> objects,
                                   const scanner::sim::VirtualScanner& scanner,
                                   const DatabaseBuildOptions& options,
                                   const std::function<void(double)>& progress) {
  options.Check();
  std::set<std::string> ids;
  for (const ObjectSource& o : objects) {
    if (o.id.empty()) throw Error("build-db: an object has an empty id");
    if (!ids.insert(o.id).second) throw Error("build-db: two objects are called '" + o.id + "'");
  }
  ObjectDatabase db;
  db.parameters = options.parameters;
  const ObjectDatabaseParameters& p = options.parameters;
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  for (std::size_t k = 0; k < objects.size(); ++k) {
    const ObjectSource& source = objects[k];
    ObjectModel model;
    model.id = source.id;
    model.source = source.source;
    model.grasps = source.grasps;
    model.model = ModelCloud(source.id, source.mesh, p.voxel_m, Mix(options.seed, k));
    model.diameter_m = Diameter(model.model, model.model.size());
    std::vector<std::size_t> all(model.model.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
    model.features = ComputeFpfh(model.model, all, FpfhOptions{p.feature_radius_m, threads});
    model.symmetries_declared = source.symmetries.has_value();
    model.symmetries = source.symmetries ? *source.symmetries : DetectSymmetries(source.mesh);

    scanner::sim::SceneObject object;
    object.name = source.id;
    object.shape = scanner::sim::ObjectShape::kMesh;
    object.mesh = source.mesh;
    const std::vector<scanner::sim::SceneObject> scene = {object};
    Eigen::Vector3d centre = model.model.origin;
    std::vector<std::optional<ObjectView>> views(static_cast<std::size_t>(options.views));
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int v = 0; v < options.views; ++v) {
      const double standoff =
          options.standoffs_m[static_cast<std::size_t>(v) % options.standoffs_m.size()];
      const Eigen::Isometry3d T_O_C = ViewPose(v, options.views, centre, standoff);
      const std::uint64_t seed = Mix(Mix(options.seed, k), static_cast<std::uint64_t>(v));
      const scanner::sim::VirtualScan scan = scanner.Scan(scene, T_O_C, seed);
      if (scan.points_C.size() < kMinViewPoints) continue;
      const PointCloud cloud = MakeCloud(scan.points_C);
      const EsfResult esf = VoxelisedEsf(cloud, p.voxel_m, seed, 1);  // the views run in parallel
      if (!esf.ok) continue;
      ObjectView view;
      view.T_O_C = T_O_C;
      view.esf = esf.histogram;
      view.cloud = VoxelDownsample(cloud, VoxelFilterOptions{p.voxel_m});
      view.points = static_cast<int>(view.cloud.size());
      if (view.points < kMinViewPoints) continue;
      views[static_cast<std::size_t>(v)] = view;
    }
    for (const std::optional<ObjectView>& v : views) {
      if (v) model.views.push_back(*v);
    }
    if (model.views.empty()) {
      throw Error("build-db: no view of '" + source.id + "' holds " +
                  std::to_string(kMinViewPoints) +
                  " points (is it far smaller or larger than the scanner's field of view?)");
    }
    db.objects.push_back(std::move(model));
    if (progress) progress(static_cast<double>(k + 1) / static_cast<double>(objects.size()));
  }
  return db;
}

}  // namespace uwscan::perception
