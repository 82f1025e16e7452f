#include "apps/cli/reference_options.hpp"

#include "apps/cli/number_validators.hpp"

namespace uwscan::app {

void AddLiveReferenceOptions(CLI::App& cmd, LiveReferenceArgs& args, const std::string& what) {
  cmd.add_option("--reference", args.path,
                 "design model, earlier map report or cloud, in the map's frame: " + what +
                     " (the findings and their significance: `uwscan compare` afterwards)")
      ->check(CLI::ExistingFile);
  cmd.add_option("--reference-units", args.units, "the reference file's unit")
      ->capture_default_str()
      ->check(kReferenceUnits);
  cmd.add_option("--live-threshold", args.threshold_m,
                 "metres: deviations smaller than this count as no change (NaN)")
      ->capture_default_str()
      ->check(kNonNegativeNumber);
}

double UnitsToMetres(const std::string& units) {
  return units == "mm" ? 1e-3 : units == "cm" ? 1e-2 : 1.0;
}

std::unique_ptr<mapping::LiveDeviation> LoadLiveReference(const LiveReferenceArgs& args) {
  if (args.path.empty()) return nullptr;
  mapping::SurveyReadOptions read;
  read.units_to_m = UnitsToMetres(args.units);
  mapping::LiveDeviationOptions options;
  options.threshold_m = args.threshold_m;
  return std::make_unique<mapping::LiveDeviation>(mapping::ReadSurvey(args.path, read), options);
}

}  // namespace uwscan::app
