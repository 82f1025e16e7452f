#include "apps/viewer/plot_commands.hpp"

#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli/data_folder.hpp"
#include "apps/cli/json_output.hpp"
#include "apps/cli/number_validators.hpp"
#include "apps/cli/output_path.hpp"
#include "apps/cli/progress_bar.hpp"
#include "scanner/common/atomic_file.hpp"
#include "scanner/common/error.hpp"
#include "viewer/plots/bench_plots.hpp"
#include "viewer/plots/chart_png.hpp"
#include "viewer/render/display.hpp"
#include "viewer/render/viewer_benchmark.hpp"

namespace uwscan::app {
namespace {

namespace fs = std::filesystem;

constexpr int kPanelWidthPx = 760;
constexpr int kPanelHeightPx = 560;

// Writes the charts of a bench JSON; returns which bench it was.
std::string PlotFile(const fs::path& json, const fs::path& png) {
  const viewer::BenchPlots plots = viewer::ReadBenchPlots(json);
  viewer::SavePlotsPng(plots.plots, png, kPanelWidthPx * static_cast<int>(plots.plots.size()),
                       kPanelHeightPx);
  return plots.bench;
}

struct PlotArgs {
  std::string report;
  std::string output;
};

void RunPlot(const PlotArgs& a) {
  CheckOutputPath(a.output, "-o", {a.report});
  viewer::RequireDisplay();
  const std::string bench = PlotFile(a.report, a.output);
  std::printf("%s: %s bench plotted\n", a.output.c_str(), bench.c_str());
}

// A shell word for any path.
std::string Quoted(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

struct BenchRun {
  std::string name;       // also the file names: NAME.json, NAME.png
  std::string arguments;  // after `uwscan bench`, without --json
};

// The quick form of every bench: a run in minutes whose figures keep their order. `data` is the
// --data folder the user gave, or empty: the benches then read the data folder themselves.
std::vector<BenchRun> QuickBenches(const std::string& data) {
  const std::string data_option = data.empty() ? "" : " --data " + Quoted(data);
  const fs::path slam_scene = DataFolderOr(data) / "scenes" / "inspection_short.yaml";
  return {
      {"triangulation",
       "triangulation --points 200000 --sweep-grid-px 1 2 4 8 16 --sweep-rays-per-fan 9 17 35 70"},
      {"stripe", "stripe --frames 2"},
      {"deformation", "deformation"},
      {"accuracy", "accuracy --quick" + data_option},
      {"calibration", "calibration --quick" + data_option},
      {"registration", "registration --pairs-per-mesh 1 --no-open3d --sweep-voxel 0.01 0.02 0.04"},
      {"recognition", "recognition --scans 6 --views 16 --no-images --no-peers"},
      {"slam", "slam --scene " + Quoted(slam_scene.string())},
      {"viewer", "viewer --points 200000 1000000 --frames 3"}};
}

// Runs this program with `arguments`; its stdout is returned, its stderr (progress) passes.
std::pair<int, std::string> RunSelf(const std::string& arguments) {
  const std::string command = Quoted(fs::read_symlink("/proc/self/exe").string()) + " " + arguments;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) throw Error("report: cannot start " + command);
  std::string output;
  std::array<char, 4096> buffer;
  while (const std::size_t n = std::fread(buffer.data(), 1, buffer.size(), pipe))
    output.append(buffer.data(), n);
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

struct ReportArgs {
  std::string output;
  std::string data;  // empty: DataFolder()
  std::vector<std::string> only;
};

void RunReport(const ReportArgs& a) {
  viewer::RequireDisplay();
  fs::create_directories(a.output);
  std::string index =
      "# uwscan trade-offs\n\nEach section: the bench's quick form (`uwscan report`), its table "
      "as the bench printed it, and its chart (`uwscan plot`).\n";
  int failed = 0;
  for (const BenchRun& bench : QuickBenches(a.data)) {
    if (!a.only.empty() && std::find(a.only.begin(), a.only.end(), bench.name) == a.only.end())
      continue;
    const fs::path json = fs::path(a.output) / (bench.name + ".json");
    const fs::path png = fs::path(a.output) / (bench.name + ".png");
    const std::string arguments = "bench " + bench.arguments + " --json " + Quoted(json.string());
    std::fprintf(stderr, "report: uwscan %s\n", arguments.c_str());
    const auto start = std::chrono::steady_clock::now();
    const auto [code, output] = RunSelf(arguments);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    index += "\n## " + bench.name + "\n\n`uwscan bench " + bench.arguments + "` (" +
             std::to_string(static_cast<int>(std::lround(seconds))) + " s)\n\n";
    std::string failure;
    if (code != 0) {
      failure = output.empty() ? "exit code " + std::to_string(code)
                               : output.substr(0, output.find_last_not_of('\n') + 1);
    } else {
      try {
        PlotFile(json, png);
      } catch (const Error& e) {
        failure = e.what();
      }
    }
    index += output + "\n";
    if (failure.empty()) {
      index += "![" + bench.name + "](" + bench.name + ".png)\n";
    } else {
      index += "**Not drawn**: " + failure + "\n";
      ++failed;
    }
    std::printf("%s: %s (%.0f s)\n", bench.name.c_str(),
                failure.empty() ? png.string().c_str() : "failed", seconds);
  }
  const fs::path index_path = fs::path(a.output) / "index.md";
  WriteFileAtomically(index_path, index);
  std::printf("%s: written\n", index_path.string().c_str());
  if (failed > 0)
    throw Error("report: " + std::to_string(failed) + " bench(es) failed; see " +
                index_path.string());
}

struct ViewerBenchArgs {
  std::vector<std::size_t> points = {1'000'000, 5'000'000};
  int frames = 5;
  bool edl = false;
  std::string json;
};

void RunViewerBench(const ViewerBenchArgs& a) {
  if (!a.json.empty()) CheckOutputPath(a.json, "--json");
  viewer::ViewerBenchOptions o;
  o.point_counts = a.points;
  o.frames = a.frames;
  o.eye_dome_lighting = a.edl;
  std::vector<viewer::ViewerBenchRow> rows;
  {
    ProgressBar bar;
    rows = viewer::RunViewerBenchmark(o, [&bar](double f) { bar.Update("render", f); });
  }
  std::printf("Viewer, %dx%d offscreen, vtkPointGaussianMapper points coloured by height%s\n\n",
              o.width_px, o.height_px, o.eye_dome_lighting ? ", Eye-Dome Lighting" : "");
  std::printf(
      "| points | first picture s | per frame s (median) | fastest frame s | RSS MB | held by the "
      "view MB |\n");
  std::printf("|---:|---:|---:|---:|---:|---:|\n");
  nlohmann::json json_rows = nlohmann::json::array();
  for (const viewer::ViewerBenchRow& r : rows) {
    std::printf("| %zu | %.3f | %.3f | %.3f | %.0f | %.0f |\n", r.points, r.first_picture_s,
                r.frame_s, r.frame_min_s, r.rss_shown_mb, r.held_mb());
    json_rows.push_back({{"points", r.points},
                         {"first_picture_s", r.first_picture_s},
                         {"frame_s", r.frame_s},
                         {"frame_min_s", r.frame_min_s},
                         {"rss_mb", r.rss_shown_mb},
                         {"held_mb", r.held_mb()}});
  }
  if (!a.json.empty()) {
    WriteJsonFile(a.json, {{"bench", "viewer"},
                           {"rows", json_rows},
                           {"width_px", o.width_px},
                           {"height_px", o.height_px},
                           {"eye_dome_lighting", o.eye_dome_lighting}});
  }
}

}  // namespace

void AddPlotCommand(CLI::App& app) {
  auto a = std::make_shared<PlotArgs>();
  CLI::App* cmd = app.add_subcommand(
      "plot", "draw a bench's JSON (uwscan bench NAME --json) as trade-off charts");
  cmd->add_option("report", a->report, "JSON written by `uwscan bench ... --json`")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", a->output, "PNG to write")->required();
  cmd->callback([a] { RunPlot(*a); });
}

void AddReportCommand(CLI::App& app) {
  auto a = std::make_shared<ReportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "report",
      "run the benches in their quick forms; write DIR/index.md with each table and its chart");
  cmd->add_option("-o,--output", a->output, "folder to write (created)")->required();
  cmd->add_option(
      "--data", a->data,
      "the data folder (scanners, scenes) of the accuracy, calibration and slam benches "
      "(default: `uwscan --data-dir`)");
  cmd->add_option("--only", a->only,
                  "only these benches (triangulation stripe deformation accuracy calibration "
                  "registration recognition slam viewer)");
  cmd->callback([a] { RunReport(*a); });
}

void AddViewerBenchCommand(CLI::App& bench) {
  auto a = std::make_shared<ViewerBenchArgs>();
  CLI::App* cmd = bench.add_subcommand(
      "viewer",
      "time to the first picture and per frame, and memory, for big clouds (needs an X display)");
  cmd->add_option("--points", a->points, "point counts (default 1000000 5000000)");
  cmd->add_option("--frames", a->frames, "frames timed per count")->check(kPositiveNumber);
  cmd->add_flag("--edl", a->edl, "with Eye-Dome Lighting");
  cmd->add_option("--json", a->json, "write the figures as JSON");
  cmd->callback([a] { RunViewerBench(*a); });
}

}  // namespace uwscan::app
