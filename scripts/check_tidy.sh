#!/usr/bin/env bash
# A small clang-tidy set over the project's C++ (use after move, dangling handles, redundant
# expressions, needless copies and moves; no function body over 80 lines, issue 51's rule: split
# it into named steps), with a build's compile_commands.json:
#   scripts/check_tidy.sh [--build DIR] [PATH...]   PATHs: files or folders (default: every
#                                                  library, bench and app source); exit 1 on any
#                                                  finding
#   scripts/check_tidy.sh [--build DIR] --since-base  only the sources changed since the commit
#                                                  in .tidy-base (the last whole tree checked
#                                                  clean), and those beside a changed header:
#                                                  what CTest runs (test clang_tidy), so CI
#                                                  fails on a new finding; exit 77 (skipped) when
#                                                  that commit is not in this clone's history
# clang-tidy parses each file whole (about 7 s of CPU per file here, 25-30 min for the tree), so
# CI checks what changed. A changed header brings only the source beside it: other sources that
# include it, and header-only code, wait for the next whole-tree run. After a whole-tree run is
# clean, put its commit in .tidy-base.
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
sources=(scanner perception mapping viewer ros bench apps)

# The library, bench and app sources changed since .tidy-base's commit, with the source of each
# changed header.
changed_since_base() {
  local base=$1
  git diff --name-only --diff-filter=d "$base" -- "${sources[@]}" |
    sed -n -e 's/\.hpp$/.cpp/p' -e '/\.cpp$/p' | sort -u |
    while read -r f; do [ -f "$f" ] && echo "$f"; done
}

if [ "${1:-}" = --since-base ]; then
  base=$(tr -d '[:space:]' < .tidy-base)
  if ! git cat-file -e "$base^{commit}" 2>/dev/null; then
    echo "check_tidy: .tidy-base's commit $base is not in this clone's history (shallow?): skipped" >&2
    exit 77
  fi
  mapfile -t files < <(changed_since_base "$base" | grep -v '_test\.cpp$' || true)
  if [ ${#files[@]} -eq 0 ]; then
    echo "check_tidy: no source changed since $base"
    exit 0
  fi
else
  paths=("$@")
  [ ${#paths[@]} -gt 0 ] || paths=("${sources[@]}")
  mapfile -t files < <(git ls-files -- "${paths[@]}" | grep '\.cpp$' | grep -v '_test\.cpp$')
  [ ${#files[@]} -gt 0 ] || { echo "check_tidy: no C++ sources under ${paths[*]}" >&2; exit 1; }
fi
log=$(mktemp)
trap 'rm -f "$log"' EXIT
# -config takes the place of .clang-tidy, whose header filter is then passed on its own.
length='{CheckOptions: [{key: readability-function-size.LineThreshold, value: 80}]}'
headers=$(sed -n "s/^HeaderFilterRegex: '\(.*\)'$/\1/p" .clang-tidy)
run-clang-tidy-14 -p "$build" -j "$(nproc)" -quiet -checks="$checks,readability-function-size" \
  -config="$length" -header-filter="$headers" "${files[@]}" >>"$log" 2>&1 || true
if grep -q 'warning:\|error:' "$log"; then
  grep -A3 'warning:\|error:' "$log" >&2
  echo "check_tidy: findings in ${#files[@]} files" >&2
  exit 1
fi
echo "check_tidy: ${#files[@]} files clean"
