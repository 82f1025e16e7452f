#include "perception/preprocessing/plane_removal.hpp"

#include <omp.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

#include "scanner/common/option_checks.hpp"

namespace uwscan::perception {
namespace {

constexpr int kBatch = 64;  // hypotheses scored together; fixed, so the result is thread-free

// A plane n . p + d = 0 in the cloud's float offsets.
struct Plane {
  Eigen::Vector3f n;
  float d;
};

std::optional<Plane> PlaneThrough(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                                  const Eigen::Vector3d& p2) {
  const Eigen::Vector3d a = p1 - p0, b = p2 - p0;
  const Eigen::Vector3d n = a.cross(b);
  const double norm = n.norm();
  // Collinear or repeated points: no plane.
  if (!(norm > 1e-9 * a.norm() * b.norm())) return std::nullopt;
  const Eigen::Vector3d unit = n / norm;
  return Plane{unit.cast<float>(), static_cast<float>(-unit.dot(p0))};
}

inline bool IsInlier(const Plane& plane, const Eigen::Vector3f& p, float threshold) {
  return std::abs(plane.n.dot(p) + plane.d) <= threshold;
}

std::size_t CountInliers(const std::vector<Eigen::Vector3f>& points,
                         const std::vector<std::size_t>& active, const Plane& plane,
                         float threshold) {
  std::size_t count = 0;
  for (std::size_t i : active) count += IsInlier(plane, points[i], threshold) ? 1 : 0;
  return count;
}

// Least-squares plane (PCA) through the inliers of `plane`.
std::optional<Plane> Refit(const std::vector<Eigen::Vector3f>& points,
                           const std::vector<std::size_t>& active, const Plane& plane,
                           float threshold) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::size_t count = 0;
  for (std::size_t i : active) {
    if (!IsInlier(plane, points[i], threshold)) continue;
    sum += points[i].cast<double>();
    ++count;
  }
  if (count < 3) return std::nullopt;
  const Eigen::Vector3d mean = sum / static_cast<double>(count);
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (std::size_t i : active) {
    if (!IsInlier(plane, points[i], threshold)) continue;
    const Eigen::Vector3d d = points[i].cast<double>() - mean;
    covariance.noalias() += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  const Eigen::Vector3d normal = solver.eigenvectors().col(0).normalized();
  if (!normal.allFinite()) return std::nullopt;
  return Plane{normal.cast<float>(), static_cast<float>(-normal.dot(mean))};
}

struct Candidate {
  Plane plane;
  std::size_t inliers;
};

// The best plane of one RANSAC search over the active points (at least 3 of them).
std::optional<Candidate> FindPlane(const PointCloud& cloud, const std::vector<std::size_t>& active,
                                   const PlaneRemovalOptions& options, int threads,
                                   std::mt19937_64& rng) {
  const float threshold = static_cast<float>(options.distance_threshold_m);
  const std::size_t m = active.size();
  std::uniform_int_distribution<std::size_t> pick(0, m - 1);
  std::optional<Candidate> best;
  int needed = options.max_iterations;
  std::vector<std::optional<Plane>> hypotheses;
  std::vector<std::size_t> counts;
  for (int drawn = 0; drawn < needed;) {
    const int batch = std::min(kBatch, needed - drawn);
    hypotheses.clear();
    for (int h = 0; h < batch; ++h) {
      const std::size_t a = pick(rng);
      std::size_t b = pick(rng);
      while (b == a) b = pick(rng);
      std::size_t c = pick(rng);
      while (c == a || c == b) c = pick(rng);
      hypotheses.push_back(PlaneThrough(cloud.points[active[a]].cast<double>(),
                                        cloud.points[active[b]].cast<double>(),
                                        cloud.points[active[c]].cast<double>()));
    }
    counts.assign(hypotheses.size(), 0);
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (int h = 0; h < batch; ++h) {
      const std::optional<Plane>& plane = hypotheses[static_cast<std::size_t>(h)];
      if (plane) {
        counts[static_cast<std::size_t>(h)] = CountInliers(cloud.points, active, *plane, threshold);
      }
    }
    for (int h = 0; h < batch; ++h) {
      const std::size_t count = counts[static_cast<std::size_t>(h)];
      if (hypotheses[static_cast<std::size_t>(h)] && (!best || count > best->inliers)) {
        best = Candidate{*hypotheses[static_cast<std::size_t>(h)], count};
      }
    }
    drawn += batch;
    if (best && best->inliers > 0) {
      const double w = static_cast<double>(best->inliers) / static_cast<double>(m);
      const double miss = 1.0 - w * w * w;  // a sample is not all-inlier
      const double k =
          miss <= 1e-12 ? 1.0 : std::ceil(std::log(1.0 - options.probability) / std::log(miss));
      needed = static_cast<int>(std::clamp(k, 1.0, static_cast<double>(options.max_iterations)));
    }
  }
  if (best && options.refine) {
    if (const std::optional<Plane> refined = Refit(cloud.points, active, best->plane, threshold)) {
      const std::size_t count = CountInliers(cloud.points, active, *refined, threshold);
      if (count >= best->inliers) best = Candidate{*refined, count};
    }
  }
  return best;
}

}  // namespace

void PlaneRemovalOptions::Check() const {
  const OptionChecks check("PlaneRemovalOptions");
  check.Positive("distance_threshold_m", distance_threshold_m, "m");
  check.InRange("min_fraction", min_fraction, 0.0, 1.0, Interval::kOpenLow);
  check.AtLeast("max_planes", max_planes, 0);
  check.AtLeast("max_iterations", max_iterations, 1);
  check.InRange("probability", probability, 0.0, 1.0, Interval::kOpen);
  check.AtLeast("threads", threads, 0);
}

PlaneRemovalResult RemovePlanes(const PointCloud& cloud, const PlaneRemovalOptions& options) {
  options.Check();
  RequireValidCloud(cloud, "RemovePlanes: input cloud", 0);
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  const std::size_t n = cloud.size();
  const std::size_t min_inliers = std::max<std::size_t>(
      3, static_cast<std::size_t>(std::ceil(options.min_fraction * static_cast<double>(n))));
  std::mt19937_64 rng(options.seed);

  PlaneRemovalResult result;
  std::vector<std::size_t> active(n);
  for (std::size_t i = 0; i < n; ++i) active[i] = i;
  const float threshold = static_cast<float>(options.distance_threshold_m);
  while (static_cast<int>(result.planes.size()) < options.max_planes &&
         active.size() >= min_inliers) {
    const std::optional<Candidate> found = FindPlane(cloud, active, options, threads, rng);
    if (!found || found->inliers < min_inliers) break;
    DetectedPlane plane;
    const Eigen::Vector3d normal = found->plane.n.cast<double>().normalized();
    plane.normal = normal;
    plane.offset_m = static_cast<double>(found->plane.d) - normal.dot(cloud.origin);
    std::vector<std::size_t> rest;
    for (std::size_t i : active) {
      (IsInlier(found->plane, cloud.points[i], threshold) ? plane.inliers : rest).push_back(i);
    }
    active = std::move(rest);
    result.planes.push_back(std::move(plane));
  }
  result.remaining_indices = std::move(active);
  result.remaining = Subset(cloud, result.remaining_indices);
  return result;
}

}  // namespace uwscan::perception
