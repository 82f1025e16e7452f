#pragma once

#include <filesystem>

#include "viewer/scene/scene.hpp"

// Drawing the change report `uwscan compare --json` writes (what an inspection found).
namespace uwscan::viewer {

// Whether a JSON file says it is a change report.
bool IsChangeReport(const std::filesystem::path& path);

// The report's core points coloured by their signed deviation where it is significant (NaN, so
// grey, elsewhere) and a label at each of the largest regions (at most `max_labels`): its id,
// mean deviation and area. Throws uwscan::Error naming the file and the field when the report or
// the deviations PLY it names cannot be read.
void AddChangeReport(const std::filesystem::path& path, Scene& scene, int max_labels = 12);

}  // namespace uwscan::viewer
