#!/bin/sh
# Runs a command in a private network namespace with only `lo` up, so that the GigE Vision fake
# camera and the programs talking to it can send no packet off this machine and see no other
# camera (DESIGN.md, Aravis traps). CTest runs the acquisition tests through this script
# (CROSSCOMPILING_EMULATOR); listing the tests needs no namespace.
case " $* " in
  *" --gtest_list_tests "*) exec "$@" ;;
esac
if ! command -v unshare >/dev/null 2>&1 || ! command -v ip >/dev/null 2>&1; then
  echo "run_in_netns: unshare (util-linux) or ip (iproute2) is missing; the acquisition tests need a private network namespace (./run deps)" >&2
  exit 1
fi
if ! unshare -n true 2>/dev/null; then
  echo "run_in_netns: cannot create a network namespace (unshare -n needs root or CAP_SYS_ADMIN); the acquisition tests need one" >&2
  exit 1
fi
exec unshare -n sh -c 'ip link set lo up && exec "$@"' run_in_netns "$@"
