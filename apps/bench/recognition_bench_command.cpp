#include "apps/bench/recognition_bench_command.hpp"

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "apps/cli/data_cache.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/progress_bar.hpp"
#include "bench/recognition/real_pair_benchmark.hpp"
#include "bench/recognition/recognition_benchmark.hpp"
#include "bench/recognition/recognition_conditions.hpp"

namespace uwscan::app {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double Mean(const std::vector<double>& v) {
  double sum = 0.0;
  for (double x : v) sum += x;
  return v.empty() ? 0.0 : sum / static_cast<double>(v.size());
}

double Ratio(int a, int b) { return b == 0 ? 0.0 : static_cast<double>(a) / b; }

// Every pipeline's confusion counts over the same rows and columns, zeros included: a row for
// each database object and for "foreign" (the meshes not in it), a column for each database
// object and "unknown".
using Confusion = std::map<std::string, std::map<std::string, int>>;
struct ConfusionShape {
  std::vector<std::string> rows, columns;
};
ConfusionShape ShapeOf(const std::vector<std::string>& object_ids) {
  ConfusionShape shape{object_ids, object_ids};
  shape.rows.push_back("foreign");
  shape.columns.push_back("unknown");
  return shape;
}
int Count(const Confusion& c, const std::string& truth, const std::string& answer) {
  const auto row = c.find(truth);
  if (row == c.end()) return 0;
  const auto n = row->second.find(answer);
  return n == row->second.end() ? 0 : n->second;
}
nlohmann::json DenseConfusion(const Confusion& c, const ConfusionShape& shape) {
  nlohmann::json dense = nlohmann::json::object();
  for (const std::string& truth : shape.rows) {
    for (const std::string& answer : shape.columns) dense[truth][answer] = Count(c, truth, answer);
  }
  return dense;
}
void PrintConfusion(const Confusion& c, const ConfusionShape& shape) {
  std::printf("| true \\ answer |");
  for (const std::string& answer : shape.columns) std::printf(" %s |", answer.c_str());
  std::printf("\n|---|");
  for (std::size_t k = 0; k < shape.columns.size(); ++k) std::printf("---:|");
  std::printf("\n");
  for (const std::string& truth : shape.rows) {
    std::printf("| %s |", truth.c_str());
    for (const std::string& answer : shape.columns) std::printf(" %d |", Count(c, truth, answer));
    std::printf("\n");
  }
}

// One line per object, then one per candidate uwscan weighed for it.
void PrintOutcomes(const std::vector<bench::ObjectOutcome>& outcomes) {
  std::printf("uwscan per object (scan, truth -> answer, its points, pose error):\n");
  for (const bench::ObjectOutcome& o : outcomes) {
    std::printf("  scan %3d  %-12s -> %-12s %6d pts, %6d in a segment of %6d", o.scan,
                o.truth.c_str(), o.answer.c_str(), o.points, o.points_in_segment, o.segment_points);
    if (o.rotation_error_rad >= 0.0) {
      std::printf("  %.2f deg %.1f mm", o.rotation_error_rad * kRadToDeg,
                  o.translation_error_m * 1e3);
    }
    if (o.equivalent_poses > 0)
      std::printf(", %d equivalent pose%s", o.equivalent_poses, o.equivalent_poses > 1 ? "s" : "");
    for (const std::string& id : o.equivalent_objects) std::printf(", or %s", id.c_str());
    if (o.free_slides + o.free_turns > 0)
      std::printf(", free: %d slide, %d turn", o.free_slides, o.free_turns);
    if (!o.why_wrong.empty()) {
      std::printf(", why: %s", o.why_wrong.c_str());
      if (const auto& t = o.truth_check) {
        std::printf(" (the truth at its pose: fitness %.2f close %.2f missing %.2f score %.3f)",
                    t->fitness, t->close, t->missing, t->score);
      }
    }
    std::printf("\n");
    for (std::size_t k = 0; k < o.candidates.size(); ++k) {
      const perception::RecognitionCandidate& c = o.candidates[k];
      std::printf(
          "      %-12s chi2 %.3f view %2d fitness %.2f close %.2f missing %.2f buried %.2f rmse "
          "%.2f mm%s",
          c.object_id.c_str(), c.chi_square, c.view, c.fitness, c.close, c.missing, c.buried,
          c.rmse_m * 1e3, c.verified ? " verified" : "");
      if (k < o.candidate_errors.size() && o.candidate_errors[k].first >= 0.0) {
        std::printf(", off by %.2f deg %.1f mm", o.candidate_errors[k].first * kRadToDeg,
                    o.candidate_errors[k].second * 1e3);
      }
      std::printf("\n");
    }
  }
}

// The value below which 95 % of `v` lie (0 for none).
double Percentile95(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, v.size() * 95 / 100)];
}

struct Args {
  bench::RecognitionBenchOptions options;
  int conditions = 0;      // > 0: the conditions of users' data instead, this many scenes each
  bool real_pair = false;  // PCL's milk carton pair against its correspondence grouping instead
  bool no_images = false;
  bool details = false;
  std::string json;
};

nlohmann::json ConditionPosesJson(const std::vector<bench::ConditionPose>& poses) {
  nlohmann::json out = nlohmann::json::array();
  for (const bench::ConditionPose& p : poses) {
    out.push_back(
        {{"scene", p.scene},
         {"object", p.object},
         {"rotation_error_rad", p.rotation_rad},
         {"translation_error_m", p.translation_m},
         {"right", p.right},
         {"strict", p.strict},
         {"right_or_reported", p.right_or_reported},
         {"equivalent_poses", p.equivalent_poses},
         {"nees_per_dimension",
          p.nees_per_dimension ? nlohmann::json(*p.nees_per_dimension) : nlohmann::json(nullptr)}});
  }
  return out;
}

// Every recognised object's pose in every condition: which are wrong, which report why, and
// where a NEES mean's tail comes from.
void PrintConditionPoses(const bench::RecognitionConditions& r) {
  std::printf(
      "\n| condition | scene | object | error (deg, mm) | right | strict | or reported | "
      "equivalents | NEES per pinned direction |\n"
      "|---|---:|---|---:|---|---|---|---:|---:|\n");
  auto yes = [](bool b) { return b ? "yes" : "no"; };
  for (const auto& [name, f] : r) {
    for (const bench::ConditionPose& p : f.poses) {
      std::printf("| %s | %d | %s | %.2f, %.2f | %s | %s | %s | %d | ", name.c_str(), p.scene,
                  p.object.c_str(), p.rotation_rad * 180.0 / std::numbers::pi,
                  p.translation_m * 1e3, yes(p.right), yes(p.strict), yes(p.right_or_reported),
                  p.equivalent_poses);
      if (p.nees_per_dimension)
        std::printf("%.2f |\n", *p.nees_per_dimension);
      else
        std::printf("- |\n");
    }
  }
}

// The conditions users' data brings (bench/recognition/recognition_conditions.hpp): a table and,
// with --json, {"conditions": {name: {recognition_rate, pose_success_rate, pose_strict_rate,
// pose_or_ambiguity_reported_rate, seconds_per_scan, pose_nees_per_dimension_mean,
// pose_nees_per_dimension_p95, objects, poses: [{scene, object, rotation_error_rad,
// translation_error_m, right, strict, right_or_reported, equivalent_poses, nees_per_dimension
// (null outside 10 degrees / 5 cm, or where the covariance pins nothing)}]}}}; --details prints
// the poses.
void RunConditions(const Args& a) {
  bench::RecognitionConditionsOptions options;
  options.scans = a.conditions;
  options.views = a.options.views;
  options.seed = a.options.seed;
  options.threads = a.options.threads;
  options.table_cache = TableCache();
  options.data_cache = DataCache();
  ProgressBar bar;
  const bench::RecognitionConditions r = bench::RunRecognitionConditions(options, bar.Callback());
  std::printf(
      "%d scenes per condition, %d views per object, %d threads\n\n| condition | recognised | "
      "pose 5 mm / 2 deg | strict | ... or its ambiguity reported | s per scan | NEES per pinned "
      "direction: mean, p95 |\n|---|---:|---:|---:|---:|---:|---:|\n",
      options.scans, options.views, options.threads);
  nlohmann::json conditions = nlohmann::json::object();
  for (const auto& [name, f] : r) {
    const double seconds = f.scans == 0 ? 0.0 : f.seconds / f.scans;
    std::printf(
        "| %s | %d/%d (%.1f %%) | %.1f %% | %.1f %% | %.1f %% | %.3f | %.2f, %.2f (%zu "
        "poses) |\n",
        name.c_str(), f.recognised, f.objects, 100.0 * Ratio(f.recognised, f.objects),
        100.0 * Ratio(f.pose_success, f.recognised), 100.0 * Ratio(f.pose_strict, f.recognised),
        100.0 * Ratio(f.pose_or_reported, f.recognised), seconds, Mean(f.nees_per_dimension),
        Percentile95(f.nees_per_dimension), f.nees_per_dimension.size());
    conditions[name] = {
        {"objects", f.objects},
        {"recognition_rate", Ratio(f.recognised, f.objects)},
        {"pose_success_rate", Ratio(f.pose_success, f.recognised)},
        {"pose_strict_rate", Ratio(f.pose_strict, f.recognised)},
        {"pose_or_ambiguity_reported_rate", Ratio(f.pose_or_reported, f.recognised)},
        {"seconds_per_scan", seconds},
        {"pose_nees_per_dimension_mean", Mean(f.nees_per_dimension)},
        {"pose_nees_per_dimension_p95", Percentile95(f.nees_per_dimension)},
        {"poses", ConditionPosesJson(f.poses)}};
  }
  if (a.details) PrintConditionPoses(r);
  if (!a.json.empty()) {
    WriteJsonFile(a.json, {{"bench", "recognition_conditions"},
                           {"scans_per_condition", options.scans},
                           {"views", options.views},
                           {"threads", options.threads},
                           {"conditions", conditions}});
  }
}

nlohmann::json PoseJson(const bench::RealPairPose& pose) {
  nlohmann::json out = {{"found", pose.T_scene_model.has_value()}, {"seconds", pose.seconds}};
  if (pose.T_scene_model) out["T_scene_model"] = MatrixJson(pose.T_scene_model->matrix());
  return out;
}

// A real scan and model no one here made, against PCL's correspondence grouping in the same
// run: {"model", "scene", "uwscan": {found, seconds, T_scene_model, database_seconds},
// "pcl_correspondence_grouping": {...}, "rotation_difference_deg", "translation_difference_m"}.
void RunRealPair(const Args& a) {
  bench::RealPairOptions options;
  options.data_cache = DataCache();
  options.table_cache = TableCache();
  options.threads = a.options.threads;
  options.seed = a.options.seed;
  const bench::RealPairFigures f = bench::RunRealPairBench(options);
  std::printf(
      "%s in %s (real Kinect data from PCL's correspondence grouping tutorial), %d threads\n\n",
      f.model.c_str(), f.scene.c_str(), options.threads);
  std::printf("| pipeline | found | s |\n|---|---|---:|\n");
  std::printf("| uwscan (taught from the cloud: %.2f s more) | %s | %.3f |\n", f.database_seconds,
              f.uwscan.T_scene_model ? "yes" : "no", f.uwscan.seconds);
  std::printf("| PCL correspondence grouping + ICP | %s | %.3f |\n",
              f.pcl.T_scene_model ? "yes" : "no", f.pcl.seconds);
  nlohmann::json out = {{"bench", "recognition_real_pair"},
                        {"model", f.model},
                        {"scene", f.scene},
                        {"uwscan", PoseJson(f.uwscan)},
                        {"pcl_correspondence_grouping", PoseJson(f.pcl)}};
  out["uwscan"]["database_seconds"] = f.database_seconds;
  if (f.rotation_difference_rad && f.translation_difference_m) {
    std::printf("\nuwscan's pose against PCL's: %.2f deg, %.1f mm at the model's centroid\n",
                *f.rotation_difference_rad * kRadToDeg, *f.translation_difference_m * 1e3);
    out["rotation_difference_deg"] = *f.rotation_difference_rad * kRadToDeg;
    out["translation_difference_m"] = *f.translation_difference_m;
  }
  if (!a.json.empty()) WriteJsonFile(a.json, out);
}

nlohmann::json PipelineJson(const bench::PipelineFigures& f, double per_scan) {
  nlohmann::json out = {
      {"recognition_rate", Ratio(f.recognised, f.objects)},
      {"recognition_or_reported_ambiguity_rate", Ratio(f.recognised_or_reported, f.objects)},
      {"pose_success_rate", Ratio(f.pose_success, f.recognised)},
      {"pose_or_reported_ambiguity_rate", Ratio(f.pose_or_reported, f.recognised)},
      {"mssd_success_rate", Ratio(f.mssd_success, f.recognised)},
      {"grasp_success_rate", Ratio(f.grasp_success, f.recognised)},
      {"foreign_unknown_rate", Ratio(f.foreign_unknown, f.foreign)},
      {"objects", f.objects},
      {"median_rotation_error_deg", Median(f.rotation_errors_rad) * kRadToDeg},
      {"median_translation_error_m", Median(f.translation_errors_m)},
      {"median_grasp_position_error_m", Median(f.grasp_position_errors_m)},
      {"median_grasp_angle_error_deg", Median(f.grasp_angle_errors_rad) * kRadToDeg},
      {"seconds_per_scan", per_scan}};
  if (!f.scan_seconds.empty()) {
    out["seconds_per_scan_p95"] = Percentile95(f.scan_seconds);
    out["seconds_per_scan_max"] = *std::max_element(f.scan_seconds.begin(), f.scan_seconds.end());
    out["scan_seconds"] = f.scan_seconds;
  }
  if (!f.pose_nees_per_dimension.empty()) {
    out["pose_nees_per_dimension_mean"] = Mean(f.pose_nees_per_dimension);
    out["pose_nees_per_dimension_median"] = Median(f.pose_nees_per_dimension);
    out["pose_nees_per_dimension_p95"] = Percentile95(f.pose_nees_per_dimension);
    out["pose_nees_poses"] = f.pose_nees_per_dimension.size();
    for (const auto& [truth, nees] : f.pose_nees_by_class) {
      out["pose_nees_per_dimension_median_by_class"][truth] = Median(nees);
    }
  }
  return out;
}

// The table of every pipeline; returns its figures as JSON.
nlohmann::json PrintPipelines(const bench::RecognitionBenchResult& r) {
  std::printf(
      "| pipeline | recognised | ... or among the objects reported to fit as well | pose 5 mm / 2 "
      "deg | ... or its ambiguity reported | MSSD < 0.1 d | "
      "grasp 5 mm / 3 deg | foreign -> unknown | median rot / trans err | s per scan |\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  nlohmann::json pipelines = nlohmann::json::object();
  for (const auto& [name, f] : r.pipelines) {
    const double per_scan = f.seconds / r.scans;
    std::printf(
        "| %s | %d/%d (%.1f %%) | %.1f %% | %.1f %% | %.1f %% | %.1f %% | %.1f %% | %d/%d | %.2f "
        "deg / %.1f mm | %.3f |\n",
        name.c_str(), f.recognised, f.objects, 100.0 * Ratio(f.recognised, f.objects),
        100.0 * Ratio(f.recognised_or_reported, f.objects),
        100.0 * Ratio(f.pose_success, f.recognised),
        100.0 * Ratio(f.pose_or_reported, f.recognised),
        100.0 * Ratio(f.mssd_success, f.recognised), 100.0 * Ratio(f.grasp_success, f.recognised),
        f.foreign_unknown, f.foreign, Median(f.rotation_errors_rad) * kRadToDeg,
        Median(f.translation_errors_m) * 1e3, per_scan);
    pipelines[name] = PipelineJson(f, per_scan);
  }
  return pipelines;
}

// uwscan's own figures: its time per scan and stages, its covariance's NEES, its confusion.
void PrintUwscanDetails(const bench::RecognitionBenchResult& r, const ConfusionShape& shape) {
  const bench::PipelineFigures& f = r.pipelines.at("uwscan");
  if (!f.scan_seconds.empty()) {
    std::printf("uwscan time per scan: p95 %.3f s, slowest %.3f s\n", Percentile95(f.scan_seconds),
                *std::max_element(f.scan_seconds.begin(), f.scan_seconds.end()));
  }
  std::printf("uwscan stages (s per scan):");
  for (const auto& [stage, s] : r.uwscan_stage_seconds)
    std::printf(" %s %.3f", stage.c_str(), s / r.scans);
  std::printf("\n");
  if (!f.pose_nees_per_dimension.empty()) {
    const std::vector<double>& nees = f.pose_nees_per_dimension;
    std::printf(
        "uwscan pose covariance: NEES per pinned direction mean %.2f, median %.2f over %zu poses "
        "within "
        "10 deg and 5 cm (1 when consistent)\n",
        Mean(nees), Median(nees), nees.size());
    std::printf("  median by class:");
    for (const auto& [truth, by_class] : f.pose_nees_by_class) {
      std::printf(" %s %.1f (%zu)", truth.c_str(), Median(by_class), by_class.size());
    }
    std::printf("\n");
  }
  std::printf("uwscan confusion (rows: the true object, columns: uwscan's answer):\n");
  PrintConfusion(f.confusion, shape);
}

// Why catalogue objects were not recognised (ObjectOutcome::why_wrong), counted and printed.
std::map<std::string, int> PrintWhyWrong(const bench::RecognitionBenchResult& r) {
  std::map<std::string, int> why_wrong;
  for (const bench::ObjectOutcome& o : r.outcomes) {
    if (!o.why_wrong.empty()) ++why_wrong[o.why_wrong];
  }
  std::printf(
      "uwscan wrong answers, the true object checked at its true pose on the segment answered "
      "for it:");
  for (const auto& [why, n] : why_wrong) std::printf(" %s %d", why.c_str(), n);
  if (why_wrong.empty()) std::printf(" none");
  std::printf("\n");
  return why_wrong;
}

void Run(Args a) {
  if (a.real_pair) {
    RunRealPair(a);
    return;
  }
  if (a.conditions > 0) {
    RunConditions(a);
    return;
  }
  a.options.images = !a.no_images;
  a.options.data_cache = DataCache();
  a.options.table_cache = TableCache();
  ProgressBar bar;
  const bench::RecognitionBenchResult r = bench::RunRecognitionBench(a.options, bar.Callback());
  std::printf("%d scans (%s), database %.1f s, simulation %.1f s\n", r.scans,
              a.options.images ? "rendered and detected frames" : "exact peaks + 0.1 px noise",
              r.database_seconds, r.simulation_seconds);
  const nlohmann::json pipelines = PrintPipelines(r);
  const ConfusionShape shape = ShapeOf(r.object_ids);
  nlohmann::json confusion = nlohmann::json::object();
  for (const auto& [name, f] : r.pipelines) confusion[name] = DenseConfusion(f.confusion, shape);
  std::map<std::string, int> why_wrong;
  if (r.pipelines.count("uwscan")) {
    PrintUwscanDetails(r, shape);
    why_wrong = PrintWhyWrong(r);
  }
  if (a.details) PrintOutcomes(r.outcomes);
  if (a.json.empty()) return;
  nlohmann::json stages(r.uwscan_stage_seconds);
  for (auto& [stage, s] : stages.items()) s = s.get<double>() / r.scans;
  WriteJsonFile(a.json, {{"scans", r.scans},
                         {"images", a.options.images},
                         {"threads", a.options.threads},
                         {"database_seconds", r.database_seconds},
                         {"ppf_training_seconds", r.ppf_training_seconds},
                         {"pipelines", pipelines},
                         {"confusion", confusion},
                         {"uwscan_wrong_answers", why_wrong},
                         {"uwscan_stage_seconds_per_scan", stages}});
}

}  // namespace

void AddRecognitionBenchCommand(CLI::App& bench) {
  auto a = std::make_shared<Args>();
  CLI::App* cmd = bench.add_subcommand(
      "recognition",
      "object recognition on simulated scans: uwscan vs PCL's ESF pipeline vs OpenCV's PPF");
  cmd->add_option("--scans", a->options.scans, "scenes scanned")->check(CLI::Range(1, 100000));
  cmd->add_option("--views", a->options.views, "database views per object")
      ->check(CLI::Range(1, 10000));
  cmd->add_flag("--no-images", a->no_images,
                "exact peaks with 0.1 px noise instead of rendered frames");
  cmd->add_flag(
      "--no-peers", [a](std::int64_t) { a->options.run_peers = false; }, "uwscan only");
  cmd->add_flag(
      "--no-ppf", [a](std::int64_t) { a->options.run_ppf = false; },
      "leave OpenCV's PPF out of the peers (about 30 s of training, then seconds per scan)");
  cmd->add_option("--threads", a->options.threads, "threads")->check(CLI::Range(1, 256));
  cmd->add_option("--seed", a->options.seed, "scene and noise seed");
  cmd->add_option("--only", a->options.only,
                  "run only these scenes (indices below --scans), to look at a case");
  cmd->add_option(
      "--scan-cache", a->options.scan_cache,
      "keep the simulated scans in this folder and read them from it in later runs (for comparing "
      "versions of the recogniser; a scan is named by a hash of its scene and of the simulator's "
      "sources, so scans made by other simulator code are never read back)");
  cmd->add_flag("--details", a->details,
                "print every object's answer and the candidates weighed for it (with --conditions: "
                "every pose's error and NEES)");
  cmd->add_option("--conditions", a->conditions,
                  "instead: recognition under the conditions users' data brings, this many scenes "
                  "each: objects taught from scans (clouds) beside the same from meshes, the "
                  "scenes seen by a depth camera (PCD with a VIEWPOINT), six CAD parts in "
                  "millimetres taught from their meshes and from scans of them, flat panels on "
                  "the seabed and on a wall")
      ->check(CLI::Range(1, 100000));
  cmd->add_flag("--real-pair", a->real_pair,
                "instead: PCL's correspondence grouping tutorial pair (a milk carton's model and a "
                "real Kinect scene), uwscan against PCL's correspondence grouping in the same run");
  cmd->add_option("--json", a->json, "write the figures as JSON");
  cmd->callback([a] { Run(*a); });
}

}  // namespace uwscan::app
