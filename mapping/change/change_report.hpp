#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mapping/change/compare_surveys.hpp"

namespace uwscan::mapping {

// The files `uwscan compare` writes (format in docs/formats.md, "Change report").

// The core points as a binary PLY that CloudCompare reads with its scalar fields: x y z
// (float64, absolute), nx ny nz, deviation_m and lod_m (float32, NaN where not inspected),
// significant (uint8: 1 changed, 0 unchanged or not inspected), inspected (uint8) and region
// (int32, -1 outside any). Atomic (a temporary renamed over the target). Throws uwscan::Error
// naming the file when it cannot be written.
void WriteDeviationsPly(const std::filesystem::path& path, const SurveyComparison& comparison);

// What WriteDeviationsPly wrote, read back (the viewer draws it). Throws uwscan::Error naming the
// file when it is missing, not this layout (another PLY: give the file `compare` wrote), or cut
// short.
struct DeviationsFile {
  std::vector<Eigen::Vector3d> points;
  std::vector<float> deviation_m, lod_m;  // NaN where not inspected
  std::vector<std::uint8_t> significant, inspected;
  std::vector<std::int32_t> region;
};
DeviationsFile ReadDeviationsPly(const std::filesystem::path& path);

// The report: surveys, alignment, areas, settings and one entry per region.
nlohmann::json ChangeReportJson(const SurveyComparison& comparison, const Survey& map,
                                const Survey& reference, const CompareOptions& options,
                                const std::string& deviations_ply);

// The regions as a Markdown table, with the areas above it.
std::string ChangeReportMarkdown(const SurveyComparison& comparison, const Survey& map,
                                 const Survey& reference);

}  // namespace uwscan::mapping
