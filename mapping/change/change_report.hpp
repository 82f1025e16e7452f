#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "mapping/change/compare_surveys.hpp"

namespace uwscan::mapping {

// The files `uwscan compare` writes (format in docs/formats.md, "Change report").

// The core points as a binary PLY that CloudCompare reads with its scalar fields: x y z
// (float64, absolute), nx ny nz, deviation_m and lod_m (float32, NaN where not inspected),
// significant (uint8: 1 changed, 0 unchanged or not inspected), inspected (uint8) and region
// (int32, -1 outside any). Atomic (a temporary renamed over the target). Throws uwscan::Error
// naming the file when it cannot be written.
void WriteDeviationsPly(const std::filesystem::path& path, const SurveyComparison& comparison);

// The report: surveys, alignment, areas, settings and one entry per region.
nlohmann::json ChangeReportJson(const SurveyComparison& comparison, const Survey& map,
                                const Survey& reference, const CompareOptions& options,
                                const std::string& deviations_ply);

// The regions as a Markdown table, with the areas above it.
std::string ChangeReportMarkdown(const SurveyComparison& comparison, const Survey& map,
                                 const Survey& reference);

}  // namespace uwscan::mapping
