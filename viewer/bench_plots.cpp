#include "viewer/bench_plots.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <fstream>
#include <nlohmann/json.hpp>

#include "scanner/common/error.hpp"

namespace uwscan::viewer {
namespace {

using nlohmann::json;

double Number(const json& j, const char* key, const std::string& file) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_number()) throw Error(file + ": field '" + key + "' missing or not a number");
  return it->get<double>();
}

PlotSeries Point(const std::string& label, double x, double y, int colour) {
  return {label, {x}, {y}, SeriesStyle::kPoints, CategoricalColour(colour)};
}

// The Pareto front of a plot's single-point series (smaller x, smaller y * y_sign better).
PlotSeries FrontOf(const std::vector<PlotSeries>& points, double y_sign) {
  std::vector<double> x, y;
  for (const PlotSeries& s : points) {
    x.push_back(s.x[0]);
    y.push_back(y_sign * s.y[0]);
  }
  PlotSeries front{"Pareto front", {}, {}, SeriesStyle::kLine, {90, 90, 90}};
  for (const std::size_t i : ParetoFront(x, y)) {
    front.x.push_back(x[i]);
    front.y.push_back(y_sign * y[i]);
  }
  return front;
}

// A vertical line at x over the y span of the other series: a limit measured in the run.
PlotSeries VerticalLine(const std::string& label, double x, const std::vector<PlotSeries>& others) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const PlotSeries& s : others) {
    for (const double y : s.y) {
      if (y > 0.0) lo = std::min(lo, y), hi = std::max(hi, y);
    }
  }
  return {label, {x, x}, {lo, hi}, SeriesStyle::kLine, {0, 0, 0}};
}

std::vector<PlotSpec> Triangulation(const json& j, const std::string& file) {
  PlotSpec p{"Triangulation: accuracy against time (one core)", "time per point (ns)", "mean error (mm)", true, true, {}, {}};
  int colour = 0;
  for (const auto& [name, m] : j.at("methods").items()) {
    double err_mm = Number(m, "mean_err_m", file) * 1e3;
    std::string label = name;
    // ray-ray is the reference the others are measured against: its own error is that against
    // the points that generated the pixels.
    if (name == "ray_ray") {
      err_mm = Number(j, "exact_vs_truth_max_m", file) * 1e3;
      label += " (max err vs generating points)";
    }
    p.series.push_back(Point(label, 1e9 / Number(m, "points_per_s", file), err_mm, colour++));
  }
  const PlotSeries front = FrontOf(p.series, 1.0);
  if (const auto limit = j.find("limit"); limit != j.end()) {
    p.series.push_back(VerticalLine("limit: table lookup + multiply-add", 1e9 / Number(*limit, "points_per_s", file), p.series));
  }
  p.series.push_back(front);
  return {p};
}

std::vector<PlotSpec> Stripe(const json& j, const std::string& file) {
  PlotSpec p{"Stripe detectors: sub-pixel error against time (2048x1088, one core)", "time per frame (us)",
             "RMSE at sigma 1.5 px", true, true, {}, {}};
  int colour = 0;
  for (const auto& [name, m] : j.at("methods").items()) {
    p.series.push_back(Point(name, 1e6 / Number(m, "frames_per_s", file), Number(m, "rmse_px_sigma1_5", file), colour++));
  }
  const PlotSeries front = FrontOf(p.series, 1.0);
  if (const auto limit = j.find("limit"); limit != j.end()) {
    p.series.push_back(VerticalLine("limit: one pass, column maximum", 1e6 / Number(*limit, "frames_per_s", file), p.series));
  }
  p.series.push_back(front);
  return {p};
}

std::vector<PlotSpec> Registration(const json& j, const std::string& file) {
  PlotSpec p{"Registration: success against time", "seconds per pair", "success rate", true, false, {}, {}};
  int colour = 0;
  for (const auto& [name, s] : j.at("pipelines").items()) {
    p.series.push_back(Point(name, Number(s, "seconds_per_pair", file), Number(s, "success_rate", file), colour++));
  }
  p.series.push_back(FrontOf(p.series, -1.0));  // higher success is better
  return {p};
}

std::vector<PlotSpec> Accuracy(const json& j, const std::string& file) {
  std::vector<PlotSpec> plots;
  if (const auto w = j.find("waypoints"); w != j.end() && !w->empty()) {
    PlotSpec rms{"MEMS: plane residual against waypoints per line", "waypoints per line", "plane rms (mm)", true, true, {}, {}};
    PlotSpec speed{"MEMS: lines per second against waypoints per line", "waypoints per line", "lines/s", true, true, {}, {}};
    PlotSeries real{"realistic", {}, {}, SeriesStyle::kLine, CategoricalColour(0)};
    PlotSeries exact{"exact peaks", {}, {}, SeriesStyle::kLine, CategoricalColour(1)};
    PlotSeries lines{"lines/s", {}, {}, SeriesStyle::kLine, CategoricalColour(2)};
    for (const json& row : *w) {
      const double n = Number(row, "waypoints_per_line", file);
      real.x.push_back(n);
      real.y.push_back(Number(row, "rms_m", file) * 1e3);
      exact.x.push_back(n);
      exact.y.push_back(Number(row, "rms_noise_free_m", file) * 1e3);
      lines.x.push_back(n);
      lines.y.push_back(Number(row, "lines_per_s", file));
    }
    rms.series = {real, exact};
    speed.series = {lines};
    plots.push_back(rms);
    plots.push_back(speed);
  }
  if (const auto plane = j.find("plane"); plane != j.end() && !plane->empty()) {
    PlotSpec p{"MEMS: plane residual against range", "range (m)", "plane rms (mm)", false, false, {}, {}};
    PlotSeries s{"plane rms", {}, {}, SeriesStyle::kLine, CategoricalColour(0)};
    for (const json& row : *plane) {
      s.x.push_back(Number(row, "distance_m", file));
      s.y.push_back(Number(row, "rms_m", file) * 1e3);
    }
    p.series = {s};
    plots.push_back(p);
  }
  if (plots.empty()) throw Error(file + ": an accuracy report without waypoint or plane rows");
  return plots;
}

std::vector<PlotSpec> Calibration(const json& j, const std::string& file) {
  PlotSpec p{"Calibration: time per step", "", "seconds", false, false, {}, {}};
  PlotSeries bars{"time", {}, {}, SeriesStyle::kBars, CategoricalColour(0)};
  for (const auto& [name, step] : j.at("steps").items()) {
    bars.x.push_back(static_cast<double>(bars.x.size() + 1));
    bars.y.push_back(Number(step, "seconds", file));
    p.x_tick_labels.push_back(name);
  }
  p.series = {bars};
  return {p};
}

std::vector<PlotSpec> Deformation(const json& j, const std::string& file) {
  PlotSpec p{"Refracted laser fan: plane and cone fit residual", "incidence (deg)", "fit rms (mm)", false, true, {}, {}};
  PlotSeries plane{"plane", {}, {}, SeriesStyle::kLine, CategoricalColour(3)};
  PlotSeries cone{"elliptic cone", {}, {}, SeriesStyle::kLine, CategoricalColour(0)};
  for (const json& row : j.at("rows")) {
    const double deg = Number(row, "incidence_deg", file);
    plane.x.push_back(deg);
    plane.y.push_back(Number(row, "plane_rms_m", file) * 1e3);
    cone.x.push_back(deg);
    cone.y.push_back(Number(row, "cone_rms_m", file) * 1e3);
  }
  p.series = {plane, cone};
  return {p};
}

std::vector<PlotSpec> Viewer(const json& j, const std::string& file) {
  PlotSpec p{"Viewer: render time against points (Xvfb, software)", "points", "seconds", true, true, {}, {}};
  PlotSeries first{"time to first picture", {}, {}, SeriesStyle::kLine, CategoricalColour(0)};
  PlotSeries frame{"per frame", {}, {}, SeriesStyle::kLine, CategoricalColour(1)};
  for (const json& row : j.at("rows")) {
    const double n = Number(row, "points", file);
    first.x.push_back(n);
    first.y.push_back(Number(row, "first_picture_s", file));
    frame.x.push_back(n);
    frame.y.push_back(Number(row, "frame_s", file));
  }
  p.series = {first, frame};
  return {p};
}

}  // namespace

BenchPlots ReadBenchPlots(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in(path);
  if (!in) throw Error(file + ": cannot read");
  json j;
  try {
    j = json::parse(in);
  } catch (const json::exception& e) {
    throw Error(file + ": not valid JSON (" + e.what() + ")");
  }
  if (!j.is_object()) throw Error(file + ": not a bench report (expected a JSON object)");
  try {
    if (j.contains("exact_vs_truth_max_m")) return {"triangulation", Triangulation(j, file)};
    if (j.contains("methods") && j.contains("image")) return {"stripe", Stripe(j, file)};
    if (j.contains("pipelines")) return {"registration", Registration(j, file)};
    if (j.contains("waypoints") || j.contains("gauges")) return {"accuracy", Accuracy(j, file)};
    if (j.contains("steps")) return {"calibration", Calibration(j, file)};
    if (j.value("bench", std::string()) == "viewer") return {"viewer", Viewer(j, file)};
    if (j.contains("rows")) return {"deformation", Deformation(j, file)};
  } catch (const json::exception& e) {
    throw Error(file + ": a field has the wrong type or is missing (" + e.what() + ")");
  }
  throw Error(file + ": not the JSON of a bench this uwscan can plot (triangulation, stripe, registration, "
              "accuracy, calibration, deformation, viewer)");
}

}  // namespace uwscan::viewer
