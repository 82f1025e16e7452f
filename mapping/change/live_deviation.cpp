#include "mapping/change/live_deviation.hpp"

#include <cmath>
#include <limits>

#include "perception/cloud/cloud_neighbors.hpp"
#include "perception/preprocessing/normals.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/option_checks.hpp"

namespace uwscan::mapping {

struct LiveDeviation::Impl {
  perception::PointCloud reference;  // with normals
  std::unique_ptr<perception::KnnIndex> index;
  LiveDeviationOptions options;
};

void LiveDeviationOptions::Check() const {
  const OptionChecks check("LiveDeviationOptions");
  check.Positive("max_distance_m", max_distance_m, "m");
  check.NonNegative("threshold_m", threshold_m, "m");
  check.Positive("normal_radius_m", normal_radius_m, "m");
}

LiveDeviation::LiveDeviation(const Survey& reference, const LiveDeviationOptions& options)
    : impl_(std::make_unique<Impl>()) {
  options.Check();
  if (reference.cloud.empty()) throw Error(reference.name + ": the reference has no points");
  impl_->options = options;
  if (reference.cloud.has_normals()) {
    impl_->reference = reference.cloud;
  } else {
    perception::NormalOptions normals;
    normals.radius_m = options.normal_radius_m;
    // Turned towards a point far above (NED): a survey's surfaces were seen from above.
    normals.viewpoint = perception::Centroid(reference.cloud) - Eigen::Vector3d(0, 0, 1000.0);
    impl_->reference = perception::AttachNormals(
                           reference.cloud, perception::EstimateNormals(reference.cloud, normals))
                           .cloud;
  }
  if (impl_->reference.empty())
    throw Error(reference.name + ": no point of the reference lies on a surface (normals)");
  impl_->index = std::make_unique<perception::KnnIndex>(impl_->reference.points);
}

LiveDeviation::~LiveDeviation() = default;

std::vector<float> LiveDeviation::Deviations(std::span<const Eigen::Vector3d> points_W) const {
  const perception::PointCloud& r = impl_->reference;
  const LiveDeviationOptions& o = impl_->options;
  std::vector<float> out(points_W.size(), std::numeric_limits<float>::quiet_NaN());
  std::vector<std::uint32_t> nearest;
  std::vector<float> d2;
  for (std::size_t i = 0; i < points_W.size(); ++i) {
    impl_->index->Query((points_W[i] - r.origin).cast<float>(), 1, nearest, d2);
    if (nearest.empty() || std::sqrt(d2.front()) > o.max_distance_m) continue;
    const double d =
        r.normals[nearest.front()].cast<double>().dot(points_W[i] - r.Point(nearest.front()));
    if (std::abs(d) >= o.threshold_m) out[i] = static_cast<float>(d);
  }
  return out;
}

}  // namespace uwscan::mapping
