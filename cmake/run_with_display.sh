#!/usr/bin/env bash
# Runs a command with an X display, which VTK 9.1 on Debian 12 needs even to render offscreen
# (DESIGN.md): the caller's display when it answers, else a private Xvfb through xvfb-run.
# CTest runs the viewer's tests through this script (CROSSCOMPILING_EMULATOR).
set -euo pipefail
if [ -n "${DISPLAY:-}" ] && command -v xdpyinfo >/dev/null && xdpyinfo >/dev/null 2>&1; then
  exec "$@"
fi
command -v xvfb-run >/dev/null || {
  echo "run_with_display: no X display and no xvfb-run (install xvfb and xauth: ./run deps)" >&2
  exit 1
}
# -a looks for a free server number from -n upward; a random start keeps tests that start at
# the same moment (ctest -j) from racing for the same number.
exec xvfb-run -a -n $((100 + RANDOM % 20000)) -s "-screen 0 1280x1024x24 -nolisten tcp" "$@"
