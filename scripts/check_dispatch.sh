#!/usr/bin/env bash
# Every function a library compiles for several CPUs (target_clones) is dispatched at run time:
# the library holds one resolver per such function. A compiler that drops the dispatch (clang 14
# does for a definition that has an earlier plain declaration) keeps the first clone alone, which
# passes every test on a CPU that has its instructions and stops any other with SIGILL.
# It counts: the clones must be defined in .cpp files (a header's would get a resolver in every
# file that includes it).
#   scripts/check_dispatch.sh LIBRARY SOURCE...
# CTest runs it for every library (test dispatch.NAME, cmake/UwscanHelpers.cmake).
set -euo pipefail
library=$1
shift
[ -f "$library" ] || { echo "check_dispatch: no library $library (build it first)" >&2; exit 1; }
cloned=$(cat "$@" | grep -c '^[^/]*__attribute__((target_clones(' || true)
resolvers=$(nm "$library" | grep -c '\.resolver$' || true)
if [ "$cloned" != "$resolvers" ]; then
  echo "check_dispatch: $(basename "$library"): $cloned functions with target_clones in its sources," \
       "$resolvers run-time resolvers in the library (a clone without dispatch)" >&2
  echo "  in the sources:" >&2
  grep -Hn '^[^/]*__attribute__((target_clones(' "$@" | sed 's/^/    /' >&2 || true
  echo "  resolvers:" >&2
  nm "$library" | grep '\.resolver$' | c++filt | sed 's/^/    /' >&2 || true
  exit 1
fi
echo "check_dispatch: $(basename "$library"): $cloned multiversioned functions, each dispatched"
