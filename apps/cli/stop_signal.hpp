#pragma once

namespace uwscan::app {

// SIGINT (Ctrl-C) and SIGTERM ask a long-running command (fake-camera, acquire, inspect) to
// stop: the handler only sets a flag, which the command polls and then finishes cleanly
// (every frame written, the log closed).
void InstallStopHandlers();
bool StopRequested();
int StopSignal();  // the signal that asked to stop, 0 when none
// Asks the running command to stop as a signal would (e.g. the live view's window closed).
void RequestStop();

}  // namespace uwscan::app
