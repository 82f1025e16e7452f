#include "apps/mapping/compare_command.hpp"

#include <omp.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli/data_cache.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/output_path.hpp"
#include "apps/cli/progress_bar.hpp"
#include "apps/cli/reference_options.hpp"
#include "mapping/change/change_report.hpp"
#include "mapping/change/compare_surveys.hpp"
#include "mapping/log/dive_log.hpp"
#include "mapping/slam/dive_mapping.hpp"
#include "scanner/common/atomic_file.hpp"
#include "scanner/common/error.hpp"
#include "scanner/common/temporary_folder.hpp"

namespace uwscan::app {
namespace {

struct CompareArgs {
  std::string map;
  std::string reference;
  std::string output;
  std::string json;
  std::string markdown;
  std::string reference_units = "m";
  std::vector<double> transform;  // tx ty tz qx qy qz qw
  mapping::CompareOptions options;
  int threads = 0;
};

Eigen::Isometry3d TransformOf(const std::vector<double>& v) {
  const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  if (!(std::abs(q.norm() - 1.0) < 1e-3))
    throw Error("--transform: the quaternion (qx qy qz qw) is not of unit length");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  return T;
}

void PrintFindings(const mapping::SurveyComparison& c, const std::string& output) {
  std::printf(
      "%s: %d core points %.0f mm apart; %.3f m^2 unchanged, %.3f m^2 changed, %.3f m^2 "
      "not inspected (%.2f s)\n",
      output.c_str(), c.areas.core_points, 1e3 * c.core_spacing_m, c.areas.unchanged_m2,
      c.areas.changed_m2, c.areas.not_inspected_m2, c.seconds);
  const mapping::SurveyAlignment& a = c.alignment;
  if (a.registered) {
    std::printf(
        "alignment: registered, fitness %.3f, RMS %.2f mm; %zu tiles of %.2f m, %d kept "
        "the global transform\n",
        a.global_fitness, 1e3 * a.global_rmse_m, a.tiles.size(), a.tile_m, a.tiles_kept_global);
  }
  std::printf("%zu significant regions%s\n", c.regions.size(), c.regions.empty() ? "" : ":");
  const std::size_t shown = std::min<std::size_t>(c.regions.size(), 10);
  for (std::size_t i = 0; i < shown; ++i) {
    const mapping::ChangeRegion& r = c.regions[i];
    std::printf(
        "  %2d %-6s at %.3f %.3f %.3f m: %.0f x %.0f mm, %.1f cm^2, mean %+.1f mm, extreme "
        "%+.1f mm, %.1fx its level of detection\n",
        r.id, r.mean_deviation_m > 0.0 ? "gained" : "lost", r.centroid_W.x(), r.centroid_W.y(),
        r.centroid_W.z(), 1e3 * r.extent_m.x(), 1e3 * r.extent_m.y(), 1e4 * r.area_m2,
        1e3 * r.mean_deviation_m, 1e3 * r.extreme_deviation_m, r.significance);
  }
  if (shown < c.regions.size())
    std::printf("  ... %zu more in the report\n", c.regions.size() - shown);
}

// A dive log is mapped here as `uwscan map` would with its defaults; anything else is read.
mapping::Survey LoadSurvey(const std::string& path, const mapping::SurveyReadOptions& options,
                           const char* option, int threads) {
  if (!mapping::IsSqliteFile(path)) return mapping::ReadSurvey(path, options);
  if (options.units_to_m != 1.0)
    throw Error(std::string(option) + " " + path + ": a dive log maps in metres (no units)");
  const mapping::DiveLogReader log(path);
  mapping::DiveMappingOptions mapping_options;
  mapping_options.mapper.threads = threads;
  mapping_options.mapper.spill_folder = TemporaryFolder();
  mapping_options.table_cache = TableCache();
  mapping::DiveMapping m;
  {
    ProgressBar bar;
    m = mapping::MapDive(log, mapping_options, [&bar](double f) { bar.Update("map", f); });
  }
  std::printf("%s: mapped, %zu points, %d submaps over %.1f s of dive (%.2f s)\n", path.c_str(),
              m.map.size(), m.submaps, m.dive_duration_s, m.seconds);
  return mapping::SurveyOfDive(m, path);
}

void RunCompare(const CompareArgs& a) {
  const std::vector<std::filesystem::path> inputs = {a.map, a.reference};
  CheckCloudOutputPath(a.output, "-o", inputs);
  if (!a.json.empty()) CheckOutputPath(a.json, "--json", inputs);
  if (!a.markdown.empty()) CheckOutputPath(a.markdown, "--markdown", inputs);
  if (a.threads > 0) omp_set_num_threads(a.threads);
  mapping::CompareOptions options = a.options;
  if (!a.transform.empty()) options.alignment.T_reference_map = TransformOf(a.transform);
  options.deviation.threads = a.threads;
  const mapping::Survey map = LoadSurvey(a.map, {}, "map", a.threads);
  mapping::SurveyReadOptions reference_options;
  reference_options.units_to_m = UnitsToMetres(a.reference_units);
  const mapping::Survey reference =
      LoadSurvey(a.reference, reference_options, "--reference", a.threads);
  const mapping::SurveyComparison c = mapping::CompareSurveys(map, reference, options);
  mapping::WriteDeviationsPly(a.output, c);
  if (!a.json.empty())
    WriteJsonFile(a.json, mapping::ChangeReportJson(c, map, reference, options, a.output));
  if (!a.markdown.empty())
    WriteFileAtomically(a.markdown, mapping::ChangeReportMarkdown(c, map, reference));
  PrintFindings(c, a.output);
}

}  // namespace

void AddCompareCommand(CLI::App& app) {
  auto a = std::make_shared<CompareArgs>();
  CLI::App* cmd = app.add_subcommand(
      "compare",
      "what the inspection found: a map against its design model or an earlier survey, signed "
      "deviations along the normals, each with a level of detection, significant regions");
  cmd->add_option("map", a->map,
                  "the map: a dive log (mapped as `uwscan map` does), a `uwscan map --json` "
                  "report (its poses' covariance used either way) or a cloud (.ply .pcd .xyz)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--reference", a->reference,
                  "design model (mesh: .ply with faces, .obj, .stl, .off), earlier dive log or "
                  "map report (.json), or cloud (.ply .pcd .xyz)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", a->output,
                  "core points with deviation_m, lod_m, significant, inspected, region (.ply)")
      ->required();
  cmd->add_option("--json", a->json, "report: alignment, areas, regions");
  cmd->add_option("--markdown", a->markdown, "the regions as a Markdown table");
  cmd->add_option("--reference-units", a->reference_units, "the reference file's unit")
      ->capture_default_str()
      ->check(kReferenceUnits);
  cmd->add_option("--transform", a->transform,
                  "T_reference_map as tx ty tz qx qy qz qw (metres): no global registration")
      ->expected(7);
  mapping::DeviationOptions& d = a->options.deviation;
  cmd->add_option("--confidence", d.confidence, "of the level of detection, two-sided")
      ->capture_default_str()
      ->check(CLI::Range(0.5, 0.9999));
  cmd->add_option("--core-spacing", d.core_spacing_m, "metres between core points")
      ->capture_default_str()
      ->check(kPositiveNumber);
  cmd->add_option("--cylinder-radius", d.cylinder_radius_m,
                  "metres: points averaged within this distance of each normal")
      ->capture_default_str()
      ->check(kPositiveNumber);
  cmd->add_option("--max-depth", d.max_depth_m,
                  "metres: the farthest a surface is looked for along each normal")
      ->capture_default_str()
      ->check(kPositiveNumber);
  cmd->add_option("--tile", a->options.alignment.tile_m,
                  "metres: the map registered again tile by tile (0: as a whole, the level of "
                  "detection then carries the map report's pose covariances)")
      ->capture_default_str()
      ->check(kNonNegativeNumber);
  cmd->add_option("--seen-within", a->options.seen_within_m,
                  "metres: a point counts as swept by every pose at most this much farther from "
                  "it than the nearest one (how loosely the map placed it against its tile, from "
                  "the report's pose graph information)")
      ->capture_default_str()
      ->check(kNonNegativeNumber);
  cmd->add_option("--threads", a->threads,
                  "threads (0: all cores); the output does not depend on it")
      ->check(kNonNegativeNumber);
  cmd->callback([a] { RunCompare(*a); });
}

}  // namespace uwscan::app
