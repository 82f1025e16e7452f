#!/usr/bin/env bash
# The project's C++ in the project's style (.clang-format, clang-format 14):
#   scripts/check_format.sh          list the files clang-format would change; exit 1 if any
#   scripts/check_format.sh --fix    reformat them in place
# CTest runs the check (test clang_format), so CI fails on a new violation.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
command -v clang-format-14 >/dev/null || { echo "check_format: clang-format-14 is missing (./run deps)" >&2; exit 1; }
mapfile -t files < <(git ls-files '*.cpp' '*.hpp' 2>/dev/null || find . -name '*.[ch]pp' -not -path './build*')
if [ "${1:-}" = --fix ]; then
  clang-format-14 -i --style=file "${files[@]}"
  exit 0
fi
bad=()
for f in "${files[@]}"; do
  clang-format-14 --style=file --dry-run -Werror "$f" >/dev/null 2>&1 || bad+=("$f")
done
if [ ${#bad[@]} -gt 0 ]; then
  printf 'check_format: not in the project style (scripts/check_format.sh --fix rewrites them):\n' >&2
  printf '  %s\n' "${bad[@]}" >&2
  exit 1
fi
echo "check_format: ${#files[@]} files in style"
