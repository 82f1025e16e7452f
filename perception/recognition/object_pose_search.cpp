#include "perception/recognition/object_pose_search.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "perception/preprocessing/normals.hpp"
#include "perception/recognition/view_pose_hypotheses.hpp"
#include "perception/registration/coarse_alignment.hpp"
#include "scanner/common/parallel_tasks.hpp"

namespace uwscan::perception {

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

const ViewFeatures& RecognitionCache::View(std::size_t object, std::size_t view, int threads) {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::unique_ptr<ViewFeatures>& slot = described_[{object, view}];
  if (!slot) {
    slot = std::make_unique<ViewFeatures>(
        DescribeView(db_.objects.at(object).views.at(view), db_.parameters, threads));
  }
  return *slot;
}

const ModelIndexes& RecognitionCache::Model(std::size_t object) {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::unique_ptr<ModelIndexes>& slot = models_[object];
  if (!slot) slot = std::make_unique<ModelIndexes>(db_.objects.at(object), db_.parameters.voxel_m);
  return *slot;
}

std::vector<Eigen::Isometry3d> HalfTurns(const PointCloud& cloud) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < cloud.size(); ++i) centroid += cloud.Point(i);
  centroid /= static_cast<double>(cloud.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d d = cloud.Point(i) - centroid;
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
  std::vector<Eigen::Isometry3d> turns;
  for (int k = 0; k < 3; ++k) {
    turns.push_back(Eigen::Translation3d(centroid) *
                    Eigen::AngleAxisd(std::numbers::pi, eigen.eigenvectors().col(k)) *
                    Eigen::Translation3d(-centroid));
  }
  return turns;
}

// Point-to-plane ICP of a segment onto a model, to the scale of the data.
IcpOptions FineIcp(double diameter_m, const ObjectDatabaseParameters& p, int threads) {
  IcpOptions icp;
  icp.method = IcpMethod::kPointToPlane;
  icp.max_correspondence_distance_m = {4.0 * p.voxel_m, 2.0 * p.voxel_m, 1.5 * p.voxel_m};
  icp.translation_tolerance_m = 0.01 * p.voxel_m;
  icp.rotation_tolerance_rad = icp.translation_tolerance_m / (0.5 * diameter_m);
  icp.relative_rmse_tolerance = 1e-6;
  icp.max_iterations = 300;
  icp.max_iterations_per_stage = 100;
  // Wrong objects and poses often cycle between fits until the cap (148 of 225 fine ICPs of
  // ten scans ran a mean of 219 iterations): 10 iterations without a lower residual end a stage.
  icp.stall_iterations = 10;
  // The model has its bores and inner walls (seen through a pipe's ends), a wall's thickness
  // below its outside: a scan of the outside laid on them fits within a millimetre, a false
  // minimum (elbows settled there 2-7 degrees off). Pairs whose normals disagree are not made.
  icp.max_normal_angle_rad = std::numbers::pi / 3.0;
  icp.threads = threads;
  return icp;
}

IcpOptions FineIcpLastStage(double diameter_m, const ObjectDatabaseParameters& p, int threads) {
  IcpOptions last = FineIcp(diameter_m, p, threads);
  last.max_correspondence_distance_m = {last.max_correspondence_distance_m.back()};
  return last;
}

// Starting poses T_O_S of a segment on one object: FPFH + RANSAC onto its nearest view (when
// RANSAC finds one), then each of its nearest views rolled about the line of sight.
std::vector<Eigen::Isometry3d> PoseStarts(const PointCloud& segment,
                                          const FpfhFeatures& segment_features, std::size_t object,
                                          const std::vector<std::pair<double, int>>& views,
                                          RecognitionCache& cache, const ObjectDatabase& db,
                                          const RecognitionOptions& options) {
  const ObjectModel& model = db.objects[object];
  const ObjectDatabaseParameters& p = db.parameters;
  std::vector<Eigen::Isometry3d> starts;
  const std::size_t nearest_view = static_cast<std::size_t>(views.front().second);
  const ObjectView& nearest = model.views[nearest_view];
  const ViewFeatures& described = cache.View(object, nearest_view, options.threads);
  CoarseAlignmentOptions coarse;
  coarse.inlier_distance_m = 2.0 * p.voxel_m;
  coarse.max_iterations = 20000;
  coarse.min_inlier_fraction = 0.02;
  coarse.seed = options.seed;
  coarse.threads = options.threads;
  // The segment onto the view it resembles, which places it on the model.
  const RegistrationResult rough =
      AlignCoarse(segment, segment_features, described.cloud, described.features, coarse);
  if (rough.converged) starts.push_back(nearest.T_O_C * rough.T_target_source);
  for (int v = 0; v < std::min<int>(options.pose_views, std::ssize(views)); ++v) {
    const ObjectView& view =
        model.views[static_cast<std::size_t>(views[static_cast<std::size_t>(v)].second)];
    for (const Eigen::Isometry3d& T_O_S : ViewPoseHypotheses(segment, view, options.pose_rolls)) {
      starts.push_back(T_O_S);
    }
  }
  return starts;
}

double SiftReach(double diameter_m, double voxel_m) {
  return std::max(0.1 * diameter_m, 8.0 * voxel_m);
}

std::vector<Eigen::Isometry3d> SiftStarts(const PointCloud& segment, const IcpTarget& target,
                                          const std::vector<Eigen::Isometry3d>& starts,
                                          double diameter_m, const ObjectDatabaseParameters& p,
                                          const RecognitionOptions& options) {
  std::vector<Eigen::Isometry3d> kept;
  const std::size_t sift = static_cast<std::size_t>(options.sift_points);
  const std::size_t stride = std::max<std::size_t>(1, (segment.size() + sift - 1) / sift);
  std::vector<std::size_t> every;
  for (std::size_t i = 0; i < segment.size(); i += stride) every.push_back(i);
  if (every.size() < 3 || starts.empty()) return kept;
  const PointCloud subset = Subset(segment, every);
  IcpOptions icp;
  icp.method = IcpMethod::kPointToPlane;
  // From the sift's reach down to the fine ICP's start.
  icp.max_correspondence_distance_m = {SiftReach(diameter_m, p.voxel_m), 4.0 * p.voxel_m,
                                       2.0 * p.voxel_m};
  icp.max_iterations_per_stage = 8;
  icp.max_iterations = 20;
  icp.translation_tolerance_m = 0.1 * p.voxel_m;
  icp.rotation_tolerance_rad = icp.translation_tolerance_m / (0.5 * diameter_m);
  icp.relative_rmse_tolerance = 1e-3;
  // No normal gate here (the fine ICP has one): gating the sift too posed a few more objects
  // but recognised fewer (100 scans: 84.3 % against 87.9 %).
  icp.threads = 1;
  auto quick_icp = [&](const std::vector<Eigen::Isometry3d>& from, std::vector<double>& fitness,
                       std::vector<Eigen::Isometry3d>& moved) {
    const std::size_t first = moved.size();
    fitness.resize(first + from.size(), 0.0);
    moved.resize(first + from.size());
    RunParallelTasks(std::ssize(from), options.threads, [&](std::ptrdiff_t s) {
      const RegistrationResult quick =
          AlignIcp(subset, target, from[static_cast<std::size_t>(s)], icp);
      fitness[first + static_cast<std::size_t>(s)] = quick.fitness;
      moved[first + static_cast<std::size_t>(s)] = quick.T_target_source;
    });
  };
  std::vector<double> fitness;
  std::vector<Eigen::Isometry3d> moved;
  quick_icp(starts, fitness, moved);
  // The best pose turned half a turn about each principal axis of the model: a nearly
  // symmetric object (a valve's body) fits either way, and only a detail (its handle) decides.
  const std::size_t best =
      static_cast<std::size_t>(std::max_element(fitness.begin(), fitness.end()) - fitness.begin());
  std::vector<Eigen::Isometry3d> flipped;
  for (const Eigen::Isometry3d& half_turn : HalfTurns(target.cloud()))
    flipped.push_back(half_turn * moved[best]);
  quick_icp(flipped, fitness, moved);
  std::vector<std::size_t> order(moved.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return fitness[a] > fitness[b]; });
  // Distinct poses only: starts that ended in the same basin are refined once.
  const double same_m = p.voxel_m, same_rad = p.voxel_m / (0.5 * diameter_m);
  for (std::size_t s : order) {
    if (kept.size() == static_cast<std::size_t>(options.refined_starts)) break;
    const bool repeat = std::any_of(kept.begin(), kept.end(), [&](const Eigen::Isometry3d& k) {
      const Eigen::Isometry3d d = k.inverse() * moved[s];
      return d.translation().norm() < same_m && Eigen::AngleAxisd(d.linear()).angle() < same_rad;
    });
    if (!repeat) kept.push_back(moved[s]);
  }
  return kept;
}

double TruncatedResidual(const PointCloud& sample, const ObjectModel& model,
                         const NearestGrid& model_grid, const Eigen::Isometry3d& T_O_S,
                         double voxel_m) {
  const double cap = voxel_m * voxel_m;
  double sum = 0.0;
  for (std::size_t i = 0; i < sample.size(); ++i) {
    const Eigen::Vector3d x_O = T_O_S * sample.Point(i);
    const std::int64_t j =
        model_grid.Nearest((x_O - model.model.origin).cast<float>(), static_cast<float>(cap));
    if (j < 0) {
      sum += cap;
      continue;
    }
    const std::size_t nearest = static_cast<std::size_t>(j);
    const double along_normal =
        model.model.normals[nearest].cast<double>().dot(x_O - model.model.Point(nearest));
    sum += std::min(along_normal * along_normal, cap);
  }
  return sum;
}

namespace {

// TruncatedResidual of `sample` with the pose T_O_S turned about `axis` (of order >= 3) in steps
// of about half a voxel at the object's rim, over half a period either way: residual[k] is at
// turn (k - steps) x step.
struct PhaseProfile {
  double step_rad = 0.0;
  int steps = 0;
  std::vector<double> residual;
};

Eigen::Isometry3d TurnedAbout(const SymmetryAxis& axis, double angle_rad,
                              const Eigen::Isometry3d& T_O_S) {
  return Eigen::Translation3d(axis.point_O) *
         Eigen::AngleAxisd(angle_rad, axis.axis_O.normalized()) *
         Eigen::Translation3d(-axis.point_O) * T_O_S;
}

PhaseProfile SymmetryPhaseProfile(const PointCloud& sample, const ObjectModel& model,
                                  const NearestGrid& model_grid, const SymmetryAxis& axis,
                                  const Eigen::Isometry3d& T_O_S, double voxel_m) {
  PhaseProfile profile;
  const double period = 2.0 * std::numbers::pi / axis.order;
  profile.step_rad =
      std::min(period / 8.0, 0.5 * voxel_m / std::max(0.5 * model.diameter_m, voxel_m));
  profile.steps = static_cast<int>(std::ceil(0.5 * period / profile.step_rad));
  for (int k = -profile.steps; k <= profile.steps; ++k) {
    profile.residual.push_back(TruncatedResidual(
        sample, model, model_grid, TurnedAbout(axis, k * profile.step_rad, T_O_S), voxel_m));
  }
  return profile;
}

bool HasPhase(const PointCloud& sample, const ObjectModel& model, const SymmetryAxis& axis) {
  return axis.order >= 3 && sample.size() > 0 && model.model.has_normals();
}

}  // namespace

std::vector<Eigen::Isometry3d> SymmetryPhaseStarts(const PointCloud& sample,
                                                   const ObjectModel& model,
                                                   const NearestGrid& model_grid,
                                                   const SymmetryAxis& axis,
                                                   const Eigen::Isometry3d& T_O_S, double voxel_m) {
  if (!HasPhase(sample, model, axis)) return {};
  const PhaseProfile profile =
      SymmetryPhaseProfile(sample, model, model_grid, axis, T_O_S, voxel_m);
  const std::vector<double>& residual = profile.residual;
  const std::size_t lowest = static_cast<std::size_t>(
      std::min_element(residual.begin(), residual.end()) - residual.begin());
  const double near = residual[lowest] + 0.5 * voxel_m * voxel_m;
  std::size_t first = lowest, last = lowest;
  while (first > 0 && residual[first - 1] <= near) --first;
  while (last + 1 < residual.size() && residual[last + 1] <= near) ++last;
  std::vector<Eigen::Isometry3d> starts;
  const double lowest_turn = static_cast<double>(lowest) - profile.steps;
  const double middle_turn = std::round(0.5 * static_cast<double>(first + last)) - profile.steps;
  if (lowest_turn != 0.0)
    starts.push_back(TurnedAbout(axis, lowest_turn * profile.step_rad, T_O_S));
  if (middle_turn != 0.0 && middle_turn != lowest_turn) {
    starts.push_back(TurnedAbout(axis, middle_turn * profile.step_rad, T_O_S));
  }
  return starts;
}

bool SymmetryPhasePinned(const PointCloud& sample, const ObjectModel& model,
                         const NearestGrid& model_grid, const SymmetryAxis& axis,
                         const Eigen::Isometry3d& T_O_S, double voxel_m, double min_points) {
  if (!HasPhase(sample, model, axis)) return true;
  const std::vector<double> residual =
      SymmetryPhaseProfile(sample, model, model_grid, axis, T_O_S, voxel_m).residual;
  const auto [low, high] = std::minmax_element(residual.begin(), residual.end());
  return *high - *low >= min_points * voxel_m * voxel_m;
}

}  // namespace uwscan::perception
