#!/usr/bin/env bash
# A small clang-tidy set over the project's C++ (use after move, dangling handles, redundant
# expressions, needless copies and moves), with a build's compile_commands.json:
#   scripts/check_tidy.sh [--build DIR] [PATH...]   PATHs: files or folders (default: every
#                                                  library, bench and app source); exit 1 on any
#                                                  finding
# clang-tidy parses each file whole (about 7 s of CPU per file here, 30 min for the tree), so CI
# does not run it; run it on the files a change touches.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
build=build
if [ "${1:-}" = --build ]; then build=${2:?--build needs a folder}; shift 2; fi
command -v run-clang-tidy-14 >/dev/null || { echo "check_tidy: clang-tidy-14 is missing (./run deps)" >&2; exit 1; }
[ -f "$build/compile_commands.json" ] || { echo "check_tidy: no $build/compile_commands.json (./run build)" >&2; exit 1; }
checks='-*,bugprone-use-after-move,bugprone-move-forwarding-reference,bugprone-undelegated-constructor,'
checks+='bugprone-string-constructor,bugprone-dangling-handle,bugprone-sizeof-expression,'
checks+='bugprone-infinite-loop,performance-move-const-arg,performance-unnecessary-copy-initialization,'
checks+='performance-for-range-copy,misc-redundant-expression'
paths=("$@")
[ ${#paths[@]} -gt 0 ] || paths=(scanner perception mapping viewer ros bench apps)
mapfile -t files < <(git ls-files -- "${paths[@]}" | grep '\.cpp$' | grep -v '_test\.cpp$')
[ ${#files[@]} -gt 0 ] || { echo "check_tidy: no C++ sources under ${paths[*]}" >&2; exit 1; }
log=$(mktemp)
trap 'rm -f "$log"' EXIT
run-clang-tidy-14 -p "$build" -j "$(nproc)" -quiet -checks="$checks" "${files[@]}" >"$log" 2>&1 || true
if grep -q 'warning:\|error:' "$log"; then
  grep -A3 'warning:\|error:' "$log" >&2
  echo "check_tidy: findings in ${#files[@]} files" >&2
  exit 1
fi
echo "check_tidy: ${#files[@]} files clean"
