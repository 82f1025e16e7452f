#include "perception/object_recognizer.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "perception/cloud_neighbors.hpp"
#include "perception/clustering.hpp"
#include "perception/coarse_alignment.hpp"
#include "perception/icp.hpp"
#include "perception/normals.hpp"
#include "perception/object_database_builder.hpp"
#include "perception/plane_removal.hpp"
#include "perception/voxel_filter.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::perception {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

class StageClock {
 public:
  explicit StageClock(std::map<std::string, double>& seconds) : seconds_(seconds) {}
  void Lap(const std::string& stage) {
    const auto now = std::chrono::steady_clock::now();
    seconds_[stage] += std::chrono::duration<double>(now - last_).count();
    last_ = now;
  }

 private:
  std::map<std::string, double>& seconds_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

// Nearest view of each object by chi-square: (distance, view index) per object.
std::vector<std::pair<double, int>> NearestViews(const EsfDescriptor& esf, const ObjectDatabase& db) {
  std::vector<std::pair<double, int>> nearest;
  for (const ObjectModel& o : db.objects) {
    std::pair<double, int> best{std::numeric_limits<double>::infinity(), -1};
    for (std::size_t v = 0; v < o.views.size(); ++v) {
      const double d = ChiSquareDistance(esf.data(), o.views[v].esf.data(), 640);
      if (d < best.first) best = {d, static_cast<int>(v)};
    }
    nearest.push_back(best);
  }
  return nearest;
}

// The view's points with normals (facing its camera at the origin) and FPFH at every one.
struct ViewFeatures {
  PointCloud cloud;
  FpfhFeatures features;
};
ViewFeatures DescribeView(const ObjectView& view, const ObjectDatabaseParameters& p, int threads) {
  NormalOptions normals;
  normals.radius_m = p.normal_radius_m;
  normals.threads = threads;
  ViewFeatures v;
  v.cloud = AttachNormals(view.cloud, EstimateNormals(view.cloud, normals)).cloud;
  std::vector<std::size_t> all(v.cloud.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  v.features = ComputeFpfh(v.cloud, all, FpfhOptions{p.feature_radius_m, threads});
  return v;
}

// Share of the model surface the sensor should have seen that has no segment point within
// `radius_m`. Seen: facing the sensor (not grazing) and nearest to it along its line of sight
// (a depth buffer over direction bins about one voxel wide at the object), so parts the
// object hides from itself are not expected.
double MissingShare(const ObjectModel& o, const PointCloud& segment_O, const Eigen::Vector3d& sensor_O,
                    double radius_m) {
  const double range = (o.model.origin - sensor_O).norm();
  const double bin_rad = std::max(radius_m / std::max(range, 1e-3), 1e-4);
  // The sweep may cover only part of the object: only directions within the segment's angular
  // window (one bin of margin) are expected.
  auto angles = [&](const Eigen::Vector3d& ray) {
    return Eigen::Vector2d(std::atan2(ray.y(), ray.x()), std::asin(ray.z() / ray.norm()));
  };
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e9), hi = Eigen::Vector2d::Constant(-1e9);
  for (std::size_t i = 0; i < segment_O.size(); ++i) {
    const Eigen::Vector2d a = angles(segment_O.Point(i) - sensor_O);
    lo = lo.cwiseMin(a);
    hi = hi.cwiseMax(a);
  }
  lo.array() -= bin_rad;
  hi.array() += bin_rad;
  std::map<std::pair<long, long>, double> nearest_depth;
  std::vector<std::size_t> facing;
  std::vector<std::pair<long, long>> bins;
  for (std::size_t i = 0; i < o.model.size(); ++i) {
    const Eigen::Vector3d x = o.model.Point(i);
    const Eigen::Vector3d ray = x - sensor_O;
    const double depth = ray.norm();
    if (o.model.normals[i].cast<double>().dot(-ray / depth) < 0.3) continue;  // grazing or back
    const Eigen::Vector2d a = angles(ray);
    if ((a.array() < lo.array()).any() || (a.array() > hi.array()).any()) continue;  // not swept
    const std::pair<long, long> bin{std::lround(std::atan2(ray.y(), ray.x()) / bin_rad),
                                    std::lround(std::asin(ray.z() / depth) / bin_rad)};
    auto [it, inserted] = nearest_depth.emplace(bin, depth);
    if (!inserted) it->second = std::min(it->second, depth);
    facing.push_back(i);
    bins.push_back(bin);
  }
  const KnnIndex index(segment_O.points);
  std::vector<std::uint32_t> nearest;
  std::vector<float> squared;
  std::size_t expected = 0, missing = 0;
  for (std::size_t k = 0; k < facing.size(); ++k) {
    const Eigen::Vector3d x = o.model.Point(facing[k]);
    if ((x - sensor_O).norm() > nearest_depth[bins[k]] + radius_m) continue;  // hidden
    ++expected;
    index.Query((x - segment_O.origin).cast<float>(), 1, nearest, squared);
    if (nearest.empty() || squared[0] > radius_m * radius_m) ++missing;
  }
  return expected == 0 ? 1.0 : static_cast<double>(missing) / static_cast<double>(expected);
}

// Free directions from the ICP information (object frame, rotations about the model's centroid
// centre_O), and the covariance over the constrained ones.
void AnalyseInformation(const Matrix6d& information, double sigma_m, double length_m,
                        double ratio, const Eigen::Isometry3d& T_S_O,
                        const Eigen::Vector3d& centre_O, RecognizedObject& out) {
  // Rotations scaled by the object's radius so both halves are in metres before comparing.
  Matrix6d D = Matrix6d::Identity();
  D.topLeftCorner<3, 3>() *= 1.0 / length_m;
  const Matrix6d scaled = D * information * D;
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(scaled);
  const double largest = eigen.eigenvalues().maxCoeff();
  Matrix6d inverse_scaled = Matrix6d::Zero();
  for (int k = 0; k < 6; ++k) {
    const Eigen::Matrix<double, 6, 1> u = eigen.eigenvectors().col(k);
    if (largest > 0.0 && eigen.eigenvalues()[k] > ratio * largest) {
      inverse_scaled += u * u.transpose() / eigen.eigenvalues()[k];
      continue;
    }
    FreeDirection f;
    f.kind = "unconstrained";
    const bool rotation = u.head<3>().norm() > u.tail<3>().norm();
    f.motion = rotation ? "rotation" : "translation";
    const Eigen::Vector3d axis_O = (rotation ? u.head<3>() : u.tail<3>()).normalized();
    f.axis_S = T_S_O.linear() * axis_O;
    f.point_S = T_S_O * centre_O;
    out.free_directions.push_back(f);
  }
  out.covariance = sigma_m * sigma_m * (D * inverse_scaled * D);
}

}  // namespace

void RecognitionOptions::Check() const {
  auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  if (!positive(plane_distance_m)) throw Error("recognition: plane_distance_m must be > 0");
  if (!(plane_min_fraction > 0.0 && plane_min_fraction <= 1.0)) {
    throw Error("recognition: plane_min_fraction must be in (0, 1]");
  }
  if (!positive(cluster_tolerance_m)) throw Error("recognition: cluster_tolerance_m must be > 0");
  if (min_segment_points < 10) throw Error("recognition: min_segment_points must be >= 10");
  if (top_views < 1 || max_candidates < 1) {
    throw Error("recognition: top_views and max_candidates must be >= 1");
  }
  if (!positive(max_chi_square)) throw Error("recognition: max_chi_square must be > 0");
  if (!(min_fitness >= 0.0 && min_fitness <= 1.0) || !(max_missing >= 0.0 && max_missing <= 1.0)) {
    throw Error("recognition: min_fitness and max_missing must be in [0, 1]");
  }
  if (!(free_direction_ratio > 0.0 && free_direction_ratio < 1.0)) {
    throw Error("recognition: free_direction_ratio must be in (0, 1)");
  }
  if (threads < 0) throw Error("recognition: threads must be >= 0");
}

RecognitionResult RecognizeObjects(const PointCloud& scan, const ObjectDatabase& db,
                                   const RecognitionOptions& options) {
  options.Check();
  RequireValidCloud(scan, "scan", 1);
  if (db.objects.empty()) throw Error("recognition: the object database is empty");
  const ObjectDatabaseParameters& p = db.parameters;
  RecognitionResult result;
  StageClock clock(result.stage_seconds);

  const PointCloud down = VoxelDownsample(scan, VoxelFilterOptions{p.voxel_m});
  PlaneRemovalOptions planes;
  planes.distance_threshold_m = options.plane_distance_m;
  planes.min_fraction = options.plane_min_fraction;
  planes.max_planes = 3;
  planes.seed = options.seed;
  planes.threads = options.threads;
  const PlaneRemovalResult removed = RemovePlanes(down, planes);
  for (const DetectedPlane& plane : removed.planes) result.plane_points += plane.inliers.size();
  clock.Lap("preprocess");

  ClusteringOptions clustering;
  clustering.tolerance_m = options.cluster_tolerance_m;
  clustering.min_size = static_cast<std::size_t>(options.min_segment_points);
  const std::vector<std::vector<std::size_t>> clusters =
      EuclideanClusters(removed.remaining, clustering);
  // Every scan point goes to the segment of the voxel point nearest to it.
  std::vector<int> segment_of_down(down.size(), -1);
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    for (std::size_t i : clusters[c]) segment_of_down[removed.remaining_indices[i]] = static_cast<int>(c);
  }
  std::vector<std::vector<std::size_t>> segments(clusters.size());
  if (!clusters.empty()) {
    const KnnIndex down_index(down.points);
    std::vector<std::uint32_t> nearest;
    std::vector<float> squared;
    const Eigen::Vector3f shift = (scan.origin - down.origin).cast<float>();
    for (std::size_t i = 0; i < scan.size(); ++i) {
      down_index.Query(scan.points[i] + shift, 1, nearest, squared);
      const int s = segment_of_down[nearest[0]];
      if (s >= 0) segments[static_cast<std::size_t>(s)].push_back(i);
    }
  }
  clock.Lap("segment");

  for (std::size_t c = 0; c < clusters.size(); ++c) {
    RecognizedObject object;
    object.object_id = "unknown";
    object.segment = segments[c];
    const PointCloud segment = Subset(removed.remaining, clusters[c]);
    for (std::size_t i = 0; i < segment.size(); ++i) object.centroid_S += segment.Point(i);
    object.centroid_S /= static_cast<double>(segment.size());

    NormalOptions normal_options;
    normal_options.radius_m = p.normal_radius_m;
    normal_options.threads = options.threads;
    const CloudWithNormals with_normals =
        AttachNormals(segment, EstimateNormals(segment, normal_options));
    const EsfResult esf = VoxelisedEsf(segment, p.voxel_m, options.seed);
    clock.Lap("describe");
    if (!esf.ok || with_normals.cloud.size() < 10) {
      result.objects.push_back(std::move(object));
      continue;
    }
    const std::vector<std::pair<double, int>> nearest = NearestViews(esf.histogram, db);
    std::vector<std::size_t> order(db.objects.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return nearest[a].first < nearest[b].first; });
    const double extent = BoundingBoxDiagonal(segment);
    std::vector<std::size_t> candidates;
    for (std::size_t i : order) {
      if (static_cast<int>(candidates.size()) >= options.max_candidates) break;
      if (nearest[i].first > options.max_chi_square) break;
      if (extent > 1.2 * db.objects[i].diameter_m + 4.0 * p.voxel_m) continue;  // too big for it
      candidates.push_back(i);
    }
    clock.Lap("match");

    std::vector<std::size_t> all(with_normals.cloud.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
    const FpfhFeatures segment_features =
        ComputeFpfh(with_normals.cloud, all, FpfhOptions{p.feature_radius_m, options.threads});
    std::vector<RegistrationResult> fine(candidates.size());
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      const ObjectModel& model = db.objects[candidates[k]];
      RecognitionCandidate candidate;
      candidate.object_id = model.id;
      candidate.chi_square = nearest[candidates[k]].first;
      candidate.view = nearest[candidates[k]].second;
      const ObjectView& view = model.views[static_cast<std::size_t>(candidate.view)];
      const ViewFeatures described = DescribeView(view, p, options.threads);
      CoarseAlignmentOptions coarse;
      coarse.inlier_distance_m = 2.0 * p.voxel_m;
      coarse.max_iterations = 20000;
      coarse.min_inlier_fraction = 0.02;
      coarse.seed = options.seed;
      coarse.threads = options.threads;
      // The segment onto the view it resembles, which places it on the model.
      const RegistrationResult rough = AlignCoarse(with_normals.cloud, segment_features,
                                                   described.cloud, described.features, coarse);
      if (rough.converged) {
        IcpOptions icp;
        icp.method = IcpMethod::kPointToPlane;
        icp.max_correspondence_distance_m = {4.0 * p.voxel_m, 2.0 * p.voxel_m, 1.5 * p.voxel_m};
        icp.translation_tolerance_m = 0.01 * p.voxel_m;
        icp.rotation_tolerance_rad = icp.translation_tolerance_m / (0.5 * model.diameter_m);
        icp.relative_rmse_tolerance = 1e-4;
        icp.threads = options.threads;
        fine[k] = AlignIcp(with_normals.cloud, model.model, view.T_O_C * rough.T_target_source, icp);
        const Eigen::Isometry3d T_O_S = fine[k].T_target_source;
        candidate.T_S_O = T_O_S.inverse();
        candidate.fitness = fine[k].fitness;
        candidate.rmse_m = fine[k].inlier_plane_rmse;
        candidate.missing = MissingShare(model, Transformed(segment, T_O_S),
                                         T_O_S.translation(), 2.0 * p.voxel_m);
        candidate.score = candidate.fitness * (1.0 - candidate.missing);
        candidate.verified =
            candidate.fitness >= options.min_fitness && candidate.missing <= options.max_missing;
      }
      object.candidates.push_back(candidate);
    }
    clock.Lap("pose");

    // The best verified candidate by score; the candidates listed best first.
    std::vector<std::size_t> ranking(object.candidates.size());
    for (std::size_t i = 0; i < ranking.size(); ++i) ranking[i] = i;
    std::stable_sort(ranking.begin(), ranking.end(), [&](std::size_t a, std::size_t b) {
      const RecognitionCandidate &x = object.candidates[a], &y = object.candidates[b];
      if (x.verified != y.verified) return x.verified;
      return x.score > y.score;
    });
    if (!ranking.empty() && object.candidates[ranking[0]].verified) {
      const std::size_t k = ranking[0];
      const RecognitionCandidate& best = object.candidates[k];
      const ObjectModel& model = db.objects[candidates[k]];
      object.object_id = best.object_id;
      object.score = best.score;
      object.chi_square = best.chi_square;
      object.T_S_O = best.T_S_O;
      double other = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < db.objects.size(); ++i) {
        if (i != candidates[k]) other = std::min(other, nearest[i].first);
      }
      object.margin = std::isfinite(other) ? other - best.chi_square : 0.0;
      for (const SymmetryAxis& s : model.symmetries) {
        FreeDirection f;
        f.kind = "symmetry";
        f.motion = "rotation";
        f.axis_S = best.T_S_O.linear() * s.axis_O;
        f.point_S = best.T_S_O * s.point_O;
        f.order = s.order;
        object.free_directions.push_back(f);
      }
      AnalyseInformation(fine[k].information, std::max(fine[k].inlier_plane_rmse, 1e-5),
                         0.5 * model.diameter_m, options.free_direction_ratio, best.T_S_O,
                         model.model.origin, object);
      for (const GraspFrame& g : model.grasps) {
        object.grasps_S.emplace_back(g.name, best.T_S_O * g.T_O_G);
      }
    }
    std::vector<RecognitionCandidate> sorted;
    for (std::size_t i : ranking) sorted.push_back(object.candidates[i]);
    object.candidates = std::move(sorted);
    clock.Lap("verify");
    result.objects.push_back(std::move(object));
  }
  return result;
}

}  // namespace uwscan::perception
