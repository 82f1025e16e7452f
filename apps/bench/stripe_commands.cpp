#include "apps/bench/stripe_commands.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "apps/cli/json_output.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/progress_bar.hpp"
#include "bench/cpu_model.hpp"
#include "bench/scanner/stripe_benchmark.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::app {
namespace {

constexpr double kTargetFramesPerS = 2000.0;    // DESIGN.md: on one core, 2048x1088 Mono8
constexpr double kTargetFractionOfLimit = 0.5;  // of the one-pass column maximum, same run
constexpr double kTargetRmsePx = 0.05;          // DESIGN.md: clean synthetic stripes

struct StripeArgs {
  int frames = 8;
  std::uint64_t seed = 1;
  std::string json_path;
};

// The figures as JSON: the table's, the limits', the targets and the frames'.
nlohmann::json StripeJson(const bench::StripeBenchResult& result, const nlohmann::json& methods,
                          const std::string& cpu, const bench::StripeBenchOptions& options) {
  return {
      {"default", result.default_method},
      {"methods", methods},
      {"limit",
       {{"frames_per_s", result.limit_frames_per_s},
        {"what", "one pass over every pixel in row order, running maximum per column"}}},
      {"rows",
       {{"frames_per_s", result.rows.frames_per_s},
        {"fraction_of_limit", result.rows.fraction_of_limit},
        {"limit_frames_per_s", result.rows.limit_frames_per_s},
        {"what",
         "the default method along rows on the frames transposed; limit: one pass, "
         "maximum per row"}}},
      {"cpu", cpu},
      {"targets",
       {{"frames_per_s", kTargetFramesPerS},
        {"rmse_px", kTargetRmsePx},
        {"fraction_of_limit", kTargetFractionOfLimit}}},
      {"image",
       {{"width_px", options.width_px}, {"height_px", options.height_px}, {"format", "Mono8"}}}};
}

void RunStripe(const StripeArgs& args) {
  if (!args.json_path.empty()) {
    const std::filesystem::path parent = std::filesystem::path(args.json_path).parent_path();
    if (!parent.empty() && !std::filesystem::is_directory(parent)) {
      throw Error(args.json_path + ": cannot write: folder '" + parent.string() +
                  "' does not exist");
    }
  }
  bench::StripeBenchOptions options;
  options.frames = args.frames;
  options.seed = args.seed;
  const std::string cpu = bench::CpuModel();
  bench::StripeBenchResult result;
  {
    ProgressBar bar;
    result = bench::RunStripeBenchmark(options, bar.Callback());
  }
  std::printf(
      "Stripe detection, %dx%d Mono8, one core; RMSE against the exact centre of clean\n"
      "stripes (amplitude %.0f, background %.0f); targets >= %.0f frames/s (default "
      "method), RMSE <= %.2f px\n\n",
      options.width_px, options.height_px, options.amplitude, options.background, kTargetFramesPerS,
      kTargetRmsePx);
  std::printf(
      "| method | frames/s | fraction of limit | RMSE px sigma 1.5 | RMSE px sigma 3 | max err px "
      "sigma 1.5 | max err px sigma 3 | detected | RMSE target |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---|\n");
  nlohmann::json methods = nlohmann::json::object();
  for (const scanner::StripeMethod method : scanner::AllStripeMethods()) {
    const std::string name = scanner::ToString(method);
    const bench::StripeMethodFigures& m = result.methods.at(name);
    const bool meets = m.rmse_px_sigma1_5 <= kTargetRmsePx && m.rmse_px_sigma3 <= kTargetRmsePx;
    std::printf("| %s%s | %.0f | %.3f | %.4f | %.4f | %.4f | %.4f | %.4f | %s |\n", name.c_str(),
                name == result.default_method ? " (default)" : "", m.frames_per_s,
                m.fraction_of_limit, m.rmse_px_sigma1_5, m.rmse_px_sigma3, m.max_err_px_sigma1_5,
                m.max_err_px_sigma3, m.detected_fraction, meets ? "met" : "missed");
    methods[name] = {{"frames_per_s", m.frames_per_s},
                     {"fraction_of_limit", m.fraction_of_limit},
                     {"rmse_px_sigma1_5", m.rmse_px_sigma1_5},
                     {"rmse_px_sigma3", m.rmse_px_sigma3},
                     {"max_err_px_sigma1_5", m.max_err_px_sigma1_5},
                     {"max_err_px_sigma3", m.max_err_px_sigma3},
                     {"detected_fraction", m.detected_fraction},
                     {"meets_rmse_target", meets}};
  }
  const double default_fps = result.methods.at(result.default_method).frames_per_s;
  const double default_fraction = result.methods.at(result.default_method).fraction_of_limit;
  std::printf("| limit: one pass, running maximum per column | %.0f | 1 | | | | | | |\n",
              result.limit_frames_per_s);
  std::printf(
      "\nAlong rows (the frames transposed): default method %.0f frames/s, %.3f of its limit (one "
      "pass, maximum per row: %.0f frames/s)\n",
      result.rows.frames_per_s, result.rows.fraction_of_limit, result.rows.limit_frames_per_s);
  std::printf("\nCPU: %s\n", cpu.c_str());
  std::printf(
      "default method %s: %.0f frames/s (target %.0f: %s), %.3f of the limit (target %.1f: %s)\n",
      result.default_method.c_str(), default_fps, kTargetFramesPerS,
      default_fps >= kTargetFramesPerS ? "met" : "missed", default_fraction, kTargetFractionOfLimit,
      default_fraction >= kTargetFractionOfLimit ? "met" : "missed");
  if (!args.json_path.empty()) {
    WriteJsonFile(args.json_path, StripeJson(result, methods, cpu, options));
  }
}

}  // namespace

void AddStripeBenchCommand(CLI::App& bench) {
  auto args = std::make_shared<StripeArgs>();
  CLI::App* stripe = bench.add_subcommand(
      "stripe", "stripe detectors: frames/s on 2048x1088 Mono8 and sub-pixel RMSE per method");
  stripe->add_option("--frames", args->frames, "distinct frames per measurement")
      ->check(kPositiveNumber);
  stripe->add_option("--seed", args->seed, "random seed of the rendered stripes");
  stripe->add_option("--json", args->json_path, "write the figures as JSON");
  stripe->callback([args] { RunStripe(*args); });
}

}  // namespace uwscan::app
