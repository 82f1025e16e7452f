#include "apps/cli/stop_signal.hpp"

#include <signal.h>

#include <atomic>

namespace uwscan::app {
namespace {

std::atomic<int> g_stop_signal{0};
std::atomic<bool> g_stop_requested{false};
void OnStopSignal(int signal) {
  g_stop_signal.store(signal);
  g_stop_requested.store(true);
}

}  // namespace

void InstallStopHandlers() {
  g_stop_signal.store(0);
  g_stop_requested.store(false);
  struct sigaction action = {};
  action.sa_handler = OnStopSignal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool StopRequested() { return g_stop_requested.load(); }
int StopSignal() { return g_stop_signal.load(); }
void RequestStop() { g_stop_requested.store(true); }

}  // namespace uwscan::app
