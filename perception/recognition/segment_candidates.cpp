#include "perception/recognition/segment_candidates.hpp"

#include <algorithm>
#include <limits>

#include "perception/recognition/object_pose_search.hpp"

namespace uwscan::perception::recognition {

std::vector<std::vector<std::pair<double, int>>> NearestViews(const EsfDescriptor& esf,
                                                              const ObjectDatabase& db, int count) {
  std::vector<std::vector<std::pair<double, int>>> nearest;
  for (const ObjectModel& o : db.objects) {
    std::vector<std::pair<double, int>> views;
    for (std::size_t v = 0; v < o.views.size(); ++v) {
      views.emplace_back(ChiSquareDistance(esf.data(), o.views[v].esf.data(), 640),
                         static_cast<int>(v));
    }
    const auto keep = views.begin() + std::min<std::ptrdiff_t>(count, std::ssize(views));
    std::partial_sort(views.begin(), keep, views.end());
    views.erase(keep, views.end());
    if (views.empty()) views.emplace_back(std::numeric_limits<double>::infinity(), -1);
    nearest.push_back(std::move(views));
  }
  return nearest;
}

ChosenObjects ChooseObjects(const EsfDescriptor& esf, double extent_m, const ScanContext& ctx) {
  const ObjectDatabase& db = ctx.db;
  ChosenObjects c;
  c.nearest_views = NearestViews(esf, db, std::max(1, ctx.options.pose_views));
  for (const auto& views : c.nearest_views) c.nearest_chi_square.push_back(views.front().first);
  std::vector<std::size_t> order(db.objects.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return c.nearest_chi_square[a] < c.nearest_chi_square[b];
  });
  const double best_chi_square = order.empty() ? 0.0 : c.nearest_chi_square[order.front()];
  for (std::size_t i : order) {
    const double chi_square = c.nearest_chi_square[i];
    if (chi_square > ctx.options.max_chi_square) break;
    const bool fits = extent_m <= 1.1 * db.objects[i].diameter_m + 4.0 * db.parameters.voxel_m;
    const bool chosen = static_cast<int>(c.objects.size()) < ctx.options.max_candidates &&
                        chi_square <= ctx.options.max_chi_square_ratio * best_chi_square && fits;
    (chosen ? c.objects : c.others).push_back(i);
    if (!chosen && fits) c.others_that_fit.push_back(i);
  }
  return c;
}

PosedObject PoseCandidate(const DescribedSegment& s, std::size_t i, const ChosenObjects& chosen,
                          const SceneAround& around, const ScanContext& ctx) {
  const std::vector<Eigen::Isometry3d> starts =
      PoseStarts(s.cloud, s.features, i, chosen.nearest_views[i], ctx.cache, ctx.db, ctx.options);
  ctx.clock.Lap("coarse");
  PosedObject p = PoseOnSegment(s, i, starts, around, ctx);
  p.candidate.object_id = ctx.db.objects[i].id;
  p.candidate.chi_square = chosen.nearest_views[i].front().first;
  p.candidate.view = chosen.nearest_views[i].front().second;
  return p;
}

std::vector<std::size_t> PointsOnModel(const PointCloud& segment, const ObjectModel& model,
                                       const NearestGrid& model_grid,
                                       const Eigen::Isometry3d& T_O_S, double distance_m) {
  std::vector<std::size_t> on;
  const float distance_sq = static_cast<float>(distance_m * distance_m);
  for (std::size_t i = 0; i < segment.size(); ++i) {
    const Eigen::Vector3d x = T_O_S * segment.Point(i);
    if (model_grid.Nearest((x - model.model.origin).cast<float>(), distance_sq) >= 0) {
      on.push_back(i);
    }
  }
  return on;
}

}  // namespace uwscan::perception::recognition
