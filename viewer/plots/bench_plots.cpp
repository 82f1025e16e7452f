#include "viewer/plots/bench_plots.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "scanner/common/error.hpp"

namespace uwscan::viewer {
namespace {

using nlohmann::json;

double Number(const json& j, const char* key, const std::string& file) {
  const auto it = j.find(key);
  if (it == j.end() || !it->is_number())
    throw Error(file + ": field '" + key + "' missing or not a number");
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

// The resolution sweep: ray-cone error against what the table took to build, one line per
// table (the other table at its default), a point per resolution.
PlotSpec TableResolution(const json& rows, const std::string& file) {
  PlotSpec p{"Table resolution: ray-cone error against build time",
             "table build time (s)",
             "mean error (mm)",
             true,
             true,
             {},
             {},
             {}};
  PlotSeries camera{"camera-ray table, grid px", {}, {}, SeriesStyle::kLine, CategoricalColour(0)};
  PlotSeries surfaces{
      "light-surface fits, rays per fan", {}, {}, SeriesStyle::kLine, CategoricalColour(1)};
  for (const json& row : rows) {
    PlotSeries& s = row.at("table").get<std::string>() == "camera_rays" ? camera : surfaces;
    s.label.push_back(
        ' ');  // appended piecewise: GCC 12 warns falsely (-Wrestrict) on " " + string
    s.label.append(std::to_string(static_cast<int>(Number(row, "value", file))));
    s.x.push_back(Number(row, "setup_s", file));
    s.y.push_back(Number(row.at("ray_cone"), "mean_err_m", file) * 1e3);
  }
  for (PlotSeries* s : {&camera, &surfaces}) {
    if (!s->x.empty()) p.series.push_back(*s);
  }
  return p;
}

std::vector<PlotSpec> Triangulation(const json& j, const std::string& file) {
  PlotSpec p{"Triangulation: accuracy against time (one core)",
             "time per point (ns)",
             "mean error (mm)",
             true,
             true,
             {},
             {},
             {}};
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
    p.series.push_back(VerticalLine("limit: table lookup + multiply-add",
                                    1e9 / Number(*limit, "points_per_s", file), p.series));
  }
  p.series.push_back(front);
  std::vector<PlotSpec> plots = {p};
  if (const auto rows = j.find("resolution"); rows != j.end() && !rows->empty()) {
    plots.push_back(TableResolution(*rows, file));
  }
  return plots;
}

std::vector<PlotSpec> Stripe(const json& j, const std::string& file) {
  PlotSpec p{"Stripe detectors: sub-pixel error against time (2048x1088, one core)",
             "time per frame (us)",
             "RMSE at sigma 1.5 px",
             true,
             true,
             {},
             {},
             {}};
  int colour = 0;
  for (const auto& [name, m] : j.at("methods").items()) {
    p.series.push_back(Point(name, 1e6 / Number(m, "frames_per_s", file),
                             Number(m, "rmse_px_sigma1_5", file), colour++));
  }
  const PlotSeries front = FrontOf(p.series, 1.0);
  if (const auto limit = j.find("limit"); limit != j.end()) {
    p.series.push_back(VerticalLine("limit: one pass, column maximum",
                                    1e6 / Number(*limit, "frames_per_s", file), p.series));
  }
  p.series.push_back(front);
  return {p};
}

std::vector<PlotSpec> Registration(const json& j, const std::string& file) {
  PlotSpec p{"Registration: success against time",
             "seconds per pair",
             "success rate",
             true,
             false,
             {},
             {},
             {}};
  p.y_range = {{0.0, 1.05}};
  int colour = 0;
  for (const auto& [name, s] : j.at("pipelines").items()) {
    p.series.push_back(Point(name, Number(s, "seconds_per_pair", file),
                             Number(s, "success_rate", file), colour++));
  }
  p.series.push_back(FrontOf(p.series, -1.0));  // higher success is better
  // Judged modulo symmetry (ADD-S), where the bench reports it, in the next colours.
  for (const auto& [name, s] : j.at("pipelines").items()) {
    if (!s.contains("symmetric_success_rate")) continue;
    p.series.push_back(Point(name + " (ADD-S)", Number(s, "seconds_per_pair", file),
                             Number(s, "symmetric_success_rate", file), colour++));
  }
  std::vector<PlotSpec> plots = {p};
  if (const auto sweep = j.find("voxel_sweep"); sweep != j.end() && !sweep->empty()) {
    PlotSpec v{"Registration: voxel size (uwscan)",
               "voxel / object size",
               "success rate",
               true,
               false,
               {},
               {},
               {}};
    v.y_range = {{0.0, 1.05}};
    PlotSeries plain{
        "success (rotation and translation)", {}, {}, SeriesStyle::kLine, CategoricalColour(0)};
    PlotSeries adds{"ADD-S success", {}, {}, SeriesStyle::kLine, CategoricalColour(1)};
    PlotSpec t{"Registration: time against voxel size (uwscan)",
               "voxel / object size",
               "seconds per pair",
               true,
               true,
               {},
               {},
               {}};
    PlotSeries seconds{"seconds per pair", {}, {}, SeriesStyle::kLine, CategoricalColour(2)};
    for (const json& row : *sweep) {
      const double f = Number(row, "voxel_fraction", file);
      plain.x.push_back(f);
      plain.y.push_back(Number(row, "success_rate", file));
      adds.x.push_back(f);
      adds.y.push_back(Number(row, "symmetric_success_rate", file));
      seconds.x.push_back(f);
      seconds.y.push_back(Number(row, "seconds_per_pair", file));
    }
    v.series = {plain, adds};
    t.series = {seconds};
    plots.push_back(v);
    plots.push_back(t);
  }
  return plots;
}

// Recognition: each pipeline's recognition rate (and pose success among what it recognised)
// against its time per scan.
std::vector<PlotSpec> Recognition(const json& j, const std::string& file) {
  PlotSpec p{"Recognition: rate against time", "seconds per scan", "rate", true, false, {}, {}, {}};
  p.y_range = {{0.0, 1.05}};
  int colour = 0;
  for (const auto& [name, s] : j.at("pipelines").items()) {
    const double seconds = Number(s, "seconds_per_scan", file);
    p.series.push_back(
        Point(name + ": recognised", seconds, Number(s, "recognition_rate", file), colour));
    p.series.push_back(Point(name + ": pose within 5 mm, 2 deg", seconds,
                             Number(s, "pose_success_rate", file),
                             colour + 3));  // the three pipelines' recognition points take 0..2
    ++colour;
  }
  return {p};
}

// SLAM: each dive's trajectory error for dead reckoning, SLAM and Open3D's multiway
// registration against the time each took (dead reckoning at the time SLAM took, for reference).
std::vector<PlotSpec> Slam(const json& j, const std::string& file) {
  PlotSpec p{"SLAM: trajectory error against processing time",
             "seconds",
             "ATE (m)",
             true,
             true,
             {},
             {},
             {}};
  int colour = 0;
  for (const json& dive : j.at("dives")) {
    const std::string name = dive.at("name").get<std::string>();
    const double slam_s = Number(dive.at("slam"), "seconds", file);
    PlotSeries line{name, {}, {}, SeriesStyle::kLine, CategoricalColour(colour)};
    line.x = {slam_s, slam_s};
    line.y = {Number(dive.at("dr"), "ate_m", file), Number(dive.at("slam"), "ate_m", file)};
    line.label = name + ": dead reckoning -> SLAM";
    p.series.push_back(line);
    p.series.push_back(Point(name + ": SLAM", slam_s, line.y[1], colour));
    if (const auto open3d = dive.find("open3d"); open3d != dive.end() && !open3d->is_null()) {
      p.series.push_back(Point(name + ": Open3D multiway", Number(*open3d, "seconds", file),
                               Number(*open3d, "ate_m", file), colour));
    }
    ++colour;
  }
  return {p};
}

// A series of a long dive's run (bench slam --long): y against the dive's time in minutes.
PlotSeries DiveSeries(const json& run, const char* x_key, const char* y_key, double y_scale,
                      const std::string& label, int colour, const std::string& file) {
  const json& series = run.at("series");
  const std::vector<double> x = series.at(x_key).get<std::vector<double>>();
  const std::vector<double> y = series.at(y_key).get<std::vector<double>>();
  if (x.size() != y.size() || x.empty())
    throw Error(file + ": series '" + x_key + "' and '" + y_key +
                "' differ in length or are empty");
  PlotSeries line{label, {}, {}, SeriesStyle::kLine, CategoricalColour(colour)};
  for (std::size_t i = 0; i < x.size(); ++i) {
    line.x.push_back(x[i] / 60.0);
    line.y.push_back(y[i] * y_scale);
  }
  return line;
}

// Long dives: time per submap and resident memory against dive time, windowed and whole-graph
// solves, one line each per dive.
std::vector<PlotSpec> SlamLong(const json& j, const std::string& file) {
  PlotSpec time{"Mapping: time per submap against dive time",
                "dive time (min)",
                "time per submap (ms, mean of each stretch)",
                false,
                true,
                {},
                {},
                {}};
  PlotSpec memory{"Mapping: resident memory against dive time",
                  "dive time (min)",
                  "resident memory (MB)",
                  false,
                  false,
                  {},
                  {},
                  {}};
  int colour = 0;
  for (const json& dive : j.at("dives")) {
    const std::string name = dive.at("name").get<std::string>();
    std::vector<std::pair<std::string, const json*>> runs = {{name + ", windowed", &dive}};
    if (const auto whole = dive.find("full_solve"); whole != dive.end() && !whole->is_null())
      runs.emplace_back(name + ", whole graph", &*whole);
    for (const auto& [label, run] : runs) {
      time.series.push_back(
          DiveSeries(*run, "submap_time_s", "submap_seconds", 1e3, label, colour, file));
      memory.series.push_back(
          DiveSeries(*run, "rss_time_s", "rss_bytes", 1e-6, label, colour, file));
      ++colour;
    }
  }
  return {time, memory};
}

std::vector<PlotSpec> Accuracy(const json& j, const std::string& file) {
  std::vector<PlotSpec> plots;
  if (const auto w = j.find("waypoints"); w != j.end() && !w->empty()) {
    PlotSpec rms{"MEMS: plane residual against waypoints per line",
                 "waypoints per line",
                 "plane rms (mm)",
                 true,
                 true,
                 {},
                 {},
                 {}};
    PlotSpec speed{"MEMS: lines per second against waypoints per line",
                   "waypoints per line",
                   "lines/s",
                   true,
                   true,
                   {},
                   {},
                   {}};
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
    PlotSpec p{"MEMS: plane residual against range",
               "range (m)",
               "plane rms (mm)",
               false,
               false,
               {},
               {},
               {}};
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
  PlotSpec p{"Calibration: time per step", "", "seconds", false, false, {}, {}, {}};
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
  PlotSpec p{"Refracted laser fan: plane and cone fit residual",
             "incidence (deg)",
             "fit rms (mm)",
             false,
             true,
             {},
             {},
             {}};
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
  PlotSpec p{"Viewer: render time against points (Xvfb, software)",
             "points",
             "seconds",
             true,
             true,
             {},
             {},
             {}};
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
    if (j.contains("pipelines") && j.contains("confusion"))
      return {"recognition", Recognition(j, file)};
    if (j.contains("pipelines")) return {"registration", Registration(j, file)};
    if (j.value("bench", std::string()) == "slam_long") return {"slam_long", SlamLong(j, file)};
    if (j.contains("dives")) return {"slam", Slam(j, file)};
    // The calibration bench reports gauges too: its "steps" tell it from the accuracy bench.
    if (j.contains("steps")) return {"calibration", Calibration(j, file)};
    if (j.contains("waypoints") || j.contains("gauges")) return {"accuracy", Accuracy(j, file)};
    if (j.value("bench", std::string()) == "viewer") return {"viewer", Viewer(j, file)};
    if (j.contains("rows")) return {"deformation", Deformation(j, file)};
  } catch (const json::exception& e) {
    throw Error(file + ": a field has the wrong type or is missing (" + e.what() + ")");
  }
  throw Error(
      file +
      ": not the JSON of a bench this uwscan can plot (triangulation, stripe, registration, "
      "recognition, slam, slam --long, accuracy, calibration, deformation, viewer)");
}

}  // namespace uwscan::viewer
