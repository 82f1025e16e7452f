#include "viewer/plots/plot_spec.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace uwscan::viewer {

std::vector<std::size_t> ParetoFront(const std::vector<double>& x, const std::vector<double>& y) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < std::min(x.size(), y.size()); ++i) {
    if (std::isfinite(x[i]) && std::isfinite(y[i])) order.push_back(i);
  }
  // By x, ties by y: a point is on the front when its y beats every y before it.
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return x[a] < x[b] || (x[a] == x[b] && y[a] < y[b]);
  });
  std::vector<std::size_t> front;
  double best_y = std::numeric_limits<double>::infinity();
  for (const std::size_t i : order) {
    if (y[i] < best_y) {
      front.push_back(i);
      best_y = y[i];
    }
  }
  return front;
}

}  // namespace uwscan::viewer
