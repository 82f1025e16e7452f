// uwscan: the command-line program. Parses arguments and calls the libraries; errors end with
// a one-line reason on stderr and a non-zero exit.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <string>

#include "apps/bench/accuracy_command.hpp"
#include "apps/bench/acquisition_bench_command.hpp"
#include "apps/bench/bench_commands.hpp"
#include "apps/bench/calibration_bench_command.hpp"
#include "apps/bench/change_bench_command.hpp"
#include "apps/bench/kernels_command.hpp"
#include "apps/bench/recognition_bench_command.hpp"
#include "apps/bench/robustness_bench_command.hpp"
#include "apps/bench/simulation_bench_command.hpp"
#include "apps/bench/slam_bench_command.hpp"
#include "apps/bench/soak_bench_command.hpp"
#include "apps/bench/stripe_commands.hpp"
#include "apps/bench/thread_bench_command.hpp"
#include "apps/cli/data_folder.hpp"
#include "apps/mapping/compare_command.hpp"
#include "apps/mapping/inspect_command.hpp"
#include "apps/mapping/log_commands.hpp"
#include "apps/mapping/map_command.hpp"
#include "apps/perception/perception_commands.hpp"
#include "apps/perception/recognition_commands.hpp"
#include "apps/ros/bag_commands.hpp"
#include "apps/ros/ros_bench_command.hpp"
#include "apps/ros/ros_inspect_command.hpp"
#include "apps/scanner/acquisition_commands.hpp"
#include "apps/scanner/calibrate_command.hpp"
#include "apps/scanner/demo_command.hpp"
#include "apps/scanner/dive_commands.hpp"
#include "apps/scanner/object_commands.hpp"
#include "apps/viewer/plot_commands.hpp"
#include "apps/viewer/view_command.hpp"
#include "scanner/common/error.hpp"

// OpenMP's threads wait for work by sleeping, not spinning, unless the user asks otherwise:
// libgomp's default spin-wait made 2 threads slower than 1 whenever the other core was busy
// (a vehicle's computer always runs something else; docs/reliability.md, "Threads under load").
// libgomp reads OMP_WAIT_POLICY once, while the program loads, before any of uwscan's code runs.
// Even an entry in the program's .preinit_array is too early: it runs before libc installs the
// environment the program was started with, which drops what the entry set (the policy stayed
// libgomp's own). So without the variable the program starts itself again with it set: one more
// start (0.4 s here, most of it the dynamic loader), never when OMP_WAIT_POLICY is set (./run
// sets it).
namespace {
void PassiveOpenMpWaitByDefault(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr) return;
  setenv("OMP_WAIT_POLICY", "PASSIVE", /*overwrite=*/0);
  execv("/proc/self/exe", argv);
  // Not started again (no /proc): the threads keep libgomp's own policy, and say so (--version).
  unsetenv("OMP_WAIT_POLICY");
}

// The OpenMP wait policy this process runs with, as --version reports it: the variable as the
// process was started with it (/proc/self/environ, what libgomp read), not as set since.
std::string OpenMpWaitPolicy() {
  std::ifstream environ_file("/proc/self/environ", std::ios::binary);
  const std::string prefix = "OMP_WAIT_POLICY=";
  for (std::string entry; std::getline(environ_file, entry, '\0');) {
    if (entry.rfind(prefix, 0) == 0) return entry;
  }
  return "libgomp's default wait policy";
}
}  // namespace

int main(int argc, char** argv) {
  PassiveOpenMpWaitByDefault(argv);
  // A write past the file size limit (ulimit -f) fails with EFBIG, which the writers report as an
  // error naming the file and leave the old one, instead of killing the program with a core dump.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{"uwscan: underwater laser scanner perception toolkit"};
  app.set_version_flag("--version", std::string("uwscan ") + UWSCAN_VERSION +
                                        "\nOpenMP threads: " + OpenMpWaitPolicy());
  // For paths to the shipped scenes and scanners in scripts: "$(uwscan --data-dir)/scenes/...".
  app.add_flag_callback(
      "--data-dir",
      [] {
        std::printf("%s\n", uwscan::app::DataFolder().c_str());
        throw CLI::Success();
      },
      "Print the folder of uwscan's data (scanners, scenes, GenICam XML, RViz configuration) and "
      "exit: $UWSCAN_DATA_DIR, else share/uwscan of the installed program, else the source "
      "tree's data/");
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
  uwscan::app::AddCompareCommand(app);
  uwscan::app::AddViewCommand(app);
  uwscan::app::AddPlotCommand(app);
  uwscan::app::AddReportCommand(app);
  uwscan::app::AddFakeCameraCommand(app);
  uwscan::app::AddAcquireCommand(app);
  uwscan::app::AddInspectCommand(app);
  uwscan::app::AddLogCommands(app);
  uwscan::app::AddBagCommands(app);
  uwscan::app::AddRosCommands(app);
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
  uwscan::app::AddChangeBenchCommand(*bench);
  uwscan::app::AddRecognitionBenchCommand(*bench);
  uwscan::app::AddViewerBenchCommand(*bench);
  uwscan::app::AddAcquisitionBenchCommand(*bench);
  uwscan::app::AddSoakBenchCommand(*bench);
  uwscan::app::AddRosBenchCommand(*bench);
  uwscan::app::AddRobustnessBenchCommand(*bench);
  uwscan::app::AddThreadBenchCommand(*bench);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version print as CLI11 prints them; a usage error is one line, as any error.
    if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
    std::fprintf(stderr, "uwscan: error: %s (--help lists the options)\n", e.what());
    return 2;
  } catch (const uwscan::Error& e) {
    std::fprintf(stderr, "uwscan: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "uwscan: internal error: %s\n", e.what());
    return 3;
  }
  return 0;
}
