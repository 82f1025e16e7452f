#include "apps/mapping/log_commands.hpp"

#include <cstdio>
#include <filesystem>
#include <string>

#include "apps/cli/json_output.hpp"
#include "apps/cli/output_path.hpp"
#include "apps/cli/progress_bar.hpp"
#include "mapping/log/dive_log.hpp"
#include "scanner/common/error.hpp"

namespace uwscan::app {
namespace {

namespace fs = std::filesystem;

struct CheckArgs {
  std::string log;
  std::string json;
};

struct SalvageArgs {
  std::string log;
  std::string output;
  std::string json;
};

nlohmann::json ToJson(const mapping::DiveLogCheck& check) {
  nlohmann::json damage = nlohmann::json::array();
  for (const mapping::DiveLogDamage& d : check.damage) {
    damage.push_back({{"table", d.table}, {"row", d.row}, {"message", d.message}});
  }
  return {{"schema_version", check.schema_version},
          {"checksummed", check.checksummed},
          {"integrity", check.integrity},
          {"frames", check.frames},
          {"frames_intact", check.frames_intact},
          {"frames_with_damaged_truth", check.frames_with_damaged_truth},
          {"navigation", check.navigation},
          {"navigation_intact", check.navigation_intact},
          {"damage", damage},
          {"ok", check.ok()}};
}

void PrintCheck(const std::string& log, const mapping::DiveLogCheck& check) {
  std::printf("%s: schema version %d, %s\n", log.c_str(), check.schema_version,
              check.checksummed
                  ? "every row checksummed"
                  : "no checksums (schema before 3): structure and values' types only");
  std::printf("frames: %lld intact of %lld", static_cast<long long>(check.frames_intact),
              static_cast<long long>(check.frames));
  if (check.frames_with_damaged_truth > 0) {
    std::printf(" (%lld of them with ground truth that could not be read)",
                static_cast<long long>(check.frames_with_damaged_truth));
  }
  std::printf("; navigation: %lld intact of %lld\n",
              static_cast<long long>(check.navigation_intact),
              static_cast<long long>(check.navigation));
  for (const std::string& line : check.integrity)
    std::printf("sqlite quick_check: %s\n", line.c_str());
  for (const mapping::DiveLogDamage& d : check.damage)
    std::printf("damaged: %s\n", d.message.c_str());
  std::printf("%s\n", check.ok() ? "ok" : "DAMAGED");
}

void RunCheck(const CheckArgs& a) {
  if (!a.json.empty()) CheckOutputPath(a.json, "--json", {a.log});
  const mapping::DiveLogReader reader(a.log, mapping::DiveLogOpening::kDamaged);
  mapping::DiveLogCheck check;
  {
    ProgressBar bar;
    check = reader.Check({}, {}, [&](double fraction) { bar.Update("check", fraction); });
  }
  PrintCheck(a.log, check);
  if (!a.json.empty()) WriteJsonFile(a.json, ToJson(check));
  if (!check.ok()) {
    throw Error(a.log + ": damaged (" + std::to_string(check.damage.size()) + " damaged rows, " +
                std::to_string(check.integrity.size()) + " structure findings)");
  }
}

void RunSalvage(const SalvageArgs& a) {
  CheckOutputPath(a.output, "-o", {a.log});
  if (fs::exists(a.output))
    throw Error("-o " + a.output + ": exists (a dive log is never overwritten)");
  if (!a.json.empty()) CheckOutputPath(a.json, "--json", {a.log, a.output});
  const mapping::DiveLogReader reader(a.log, mapping::DiveLogOpening::kDamaged);
  mapping::DiveLogHeader header = reader.header();
  header.producer +=
      " (salvaged by uwscan log salvage from " + fs::path(a.log).filename().string() + ")";

  // Written under a temporary name and renamed when complete: the output is never a half.
  mapping::DiveLogCheck check;
  bool mount_copied = false;
  mapping::WriteDiveLogAtomically(a.output, [&](const fs::path& partial) {
    mapping::DiveLogWriter writer(partial, header);
    ProgressBar bar;
    check = reader.Check(
        [&](const mapping::FrameRecord& frame, const mapping::GroundTruthRecord* truth) {
          writer.AppendFrame(frame, truth);
        },
        [&](const mapping::NavigationRecord& sample) { writer.AppendNavigation(sample); },
        [&](double fraction) { bar.Update("salvage", fraction); });
    try {
      if (const auto mount = reader.vehicle_mount()) {
        writer.SetVehicleMount(*mount);
        mount_copied = true;
      }
    } catch (const Error&) {
      // Damaged: already in check.damage; the salvaged log goes without it.
    }
  });
  PrintCheck(a.log, check);
  const std::string without_truth = check.frames_with_damaged_truth == 0
                                        ? ""
                                        : " (" + std::to_string(check.frames_with_damaged_truth) +
                                              " without ground truth, which could not be read)";
  std::printf(
      "salvaged into %s: %lld frames%s, %lld navigation samples%s (frames renumbered from 0)\n",
      a.output.c_str(), static_cast<long long>(check.frames_intact), without_truth.c_str(),
      static_cast<long long>(check.navigation_intact), mount_copied ? ", the vehicle mount" : "");
  if (!a.json.empty()) {
    nlohmann::json json = ToJson(check);
    json["salvaged"] = {{"output", a.output},
                        {"frames", check.frames_intact},
                        {"frames_with_damaged_truth", check.frames_with_damaged_truth},
                        {"navigation", check.navigation_intact},
                        {"vehicle_mount", mount_copied}};
    WriteJsonFile(a.json, json);
  }
}

}  // namespace

void AddLogCommands(CLI::App& app) {
  CLI::App* log =
      app.add_subcommand("log", "check a dive log for damage, or salvage its intact frames");
  log->require_subcommand(1);

  auto check = std::make_shared<CheckArgs>();
  CLI::App* check_cmd = log->add_subcommand(
      "check",
      "verify every frame's and navigation sample's checksums and SQLite's own structure "
      "(exit 1 when anything is damaged)");
  check_cmd->add_option("log", check->log, "dive log (.db)")->required()->check(CLI::ExistingFile);
  check_cmd->add_option("--json", check->json, "also write the findings as JSON");
  check_cmd->callback([check] { RunCheck(*check); });

  auto salvage = std::make_shared<SalvageArgs>();
  CLI::App* salvage_cmd = log->add_subcommand("salvage",
                                              "copy every intact frame (with its ground truth when "
                                              "that is intact) and navigation sample of a "
                                              "damaged log into a new one");
  salvage_cmd->add_option("log", salvage->log, "damaged dive log (.db)")
      ->required()
      ->check(CLI::ExistingFile);
  salvage_cmd->add_option("-o,--output", salvage->output, "new dive log to write (.db)")
      ->required();
  salvage_cmd->add_option("--json", salvage->json, "also write what was kept and dropped as JSON");
  salvage_cmd->callback([salvage] { RunSalvage(*salvage); });
}

}  // namespace uwscan::app
