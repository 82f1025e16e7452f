// uwscan: the command-line program. Parses arguments and calls the libraries; errors end with
// a one-line reason on stderr and a non-zero exit.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "apps/accuracy_command.hpp"
#include "apps/acquisition_bench_command.hpp"
#include "apps/acquisition_commands.hpp"
#include "apps/bench_commands.hpp"
#include "apps/calibrate_command.hpp"
#include "apps/calibration_bench_command.hpp"
#include "apps/demo_command.hpp"
#include "apps/dive_commands.hpp"
#include "apps/inspect_command.hpp"
#include "apps/kernels_command.hpp"
#include "apps/map_command.hpp"
#include "apps/object_commands.hpp"
#include "apps/perception_commands.hpp"
#include "apps/recognition_bench_command.hpp"
#include "apps/recognition_commands.hpp"
#include "apps/plot_commands.hpp"
#include "apps/simulation_bench_command.hpp"
#include "apps/slam_bench_command.hpp"
#include "apps/stripe_commands.hpp"
#include "apps/view_command.hpp"
#include "scanner/common/error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"uwscan: underwater laser scanner perception toolkit"};
  app.set_version_flag("--version", std::string("uwscan ") + UWSCAN_VERSION);
  app.require_subcommand(1);

  uwscan::app::AddDemoCommand(app);
  uwscan::app::AddSimulateCommand(app);
  uwscan::app::AddReconstructCommand(app);
  uwscan::app::AddMakeObjectCommand(app);
  uwscan::app::AddCalibrateCommand(app);
  uwscan::app::AddImportIntrinsicsCommand(app);
  uwscan::app::AddRegisterCommand(app);
  uwscan::app::AddBuildDbCommand(app);
  uwscan::app::AddRecognizeCommand(app);
  uwscan::app::AddMapCommand(app);
  uwscan::app::AddViewCommand(app);
  uwscan::app::AddPlotCommand(app);
  uwscan::app::AddReportCommand(app);
  uwscan::app::AddFakeCameraCommand(app);
  uwscan::app::AddAcquireCommand(app);
  uwscan::app::AddInspectCommand(app);
  CLI::App* bench = app.add_subcommand("bench", "benchmarks and the seeds' experiments");
  bench->require_subcommand(1);
  uwscan::app::AddBenchCommands(*bench);
  uwscan::app::AddPerceptionBenchCommands(*bench);
  uwscan::app::AddStripeBenchCommand(*bench);
  uwscan::app::AddAccuracyBenchCommand(*bench);
  uwscan::app::AddCalibrationBenchCommand(*bench);
  uwscan::app::AddSimulationBenchCommand(*bench);
  uwscan::app::AddKernelsCommand(*bench);
  uwscan::app::AddSlamBenchCommand(*bench);
  uwscan::app::AddRecognitionBenchCommand(*bench);
  uwscan::app::AddViewerBenchCommand(*bench);
  uwscan::app::AddAcquisitionBenchCommand(*bench);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const uwscan::Error& e) {
    std::fprintf(stderr, "uwscan: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "uwscan: internal error: %s\n", e.what());
    return 2;
  }
  return 0;
}
