#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "mapping/change/live_deviation.hpp"

namespace uwscan::app {

// --reference, --reference-units and --live-threshold, as `inspect` and `ros inspect` take them
// to colour a growing map by its deviation from a design model or an earlier survey.
struct LiveReferenceArgs {
  std::string path;  // empty: none
  std::string units = "m";
  double threshold_m = mapping::LiveDeviationOptions{}.threshold_m;
};

// Adds the three options; `what` says what the reference is used for (the --reference help).
void AddLiveReferenceOptions(CLI::App& cmd, LiveReferenceArgs& args, const std::string& what);

// --reference-units's metres per unit (m, cm, mm).
double UnitsToMetres(const std::string& units);

// --reference-units's choices.
inline const CLI::Validator kReferenceUnits = CLI::IsMember({"m", "cm", "mm"});

// The reference read, ready to give deviations; nullptr when no --reference was given. Throws
// uwscan::Error naming the file when it cannot be read.
std::unique_ptr<mapping::LiveDeviation> LoadLiveReference(const LiveReferenceArgs& args);

}  // namespace uwscan::app
