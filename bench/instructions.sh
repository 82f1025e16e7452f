#!/usr/bin/env bash
# Instructions per frame and per point of the hot kernels, counted by callgrind on the fixed
# work of `uwscan bench kernels`: unlike a rate, an instruction count does not move with the
# machine's load, so two versions of the code compare exactly (memory stalls are not in it:
# pair it with the fractions of limit of `bench stripe` and `bench triangulation`).
#   bench/instructions.sh [UWSCAN_BINARY] [--json FILE]
# Needs valgrind (`./run deps` installs it). Takes under a minute.
set -euo pipefail
cd "$(dirname "$0")/.."
binary=build/bin/uwscan
json=""
while [ $# -gt 0 ]; do
  case "$1" in
    --json) json=${2:?--json needs a file}; shift 2 ;;
    *) binary=$1; shift ;;
  esac
done
command -v valgrind >/dev/null || { echo "instructions.sh: valgrind is missing (./run deps installs it)" >&2; exit 1; }
[ -x "$binary" ] || { echo "instructions.sh: $binary is not built (./run build)" >&2; exit 1; }

frames=4
points=20000
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# One run under callgrind; each kernel's inclusive instruction count from callgrind_annotate.
valgrind --tool=callgrind --callgrind-out-file="$work/cg.out" \
  "$binary" bench kernels --frames "$frames" --points "$points" >"$work/log" 2>&1 ||
  { cat "$work/log" >&2; echo "instructions.sh: callgrind failed" >&2; exit 1; }
callgrind_annotate --inclusive=yes --threshold=100 "$work/cg.out" >"$work/annotated"
count() {
  local n
  n=$(grep -F "$1" "$work/annotated" | head -n 1 | awk '{ gsub(",", "", $1); print $1 }')
  [ -n "$n" ] || { echo "instructions.sh: no count for $1" >&2; exit 1; }
  echo "$n"
}
stripe=$(count 'uwscan::scanner::StripeDetector::Detect(uwscan::scanner::StripeImage const&, uwscan::scanner::StripeDetection*)')
plane=$(count 'uwscan::scanner::RayPlaneTriangulator::TriangulateFrame(')
cone=$(count 'uwscan::scanner::RayConeTriangulator::TriangulateFrame(')
ray=$(count 'uwscan::scanner::RayRayTriangulator::TriangulateFrame(')

per() { awk -v n="$1" -v d="$2" 'BEGIN { printf "%.1f", n / d }'; }
echo "| kernel | instructions | per unit |"
echo "|---|---:|---:|"
echo "| stripe detector (default), per 2048x1088 frame | $stripe | $(per "$stripe" "$frames") |"
echo "| ray-plane, per point | $plane | $(per "$plane" "$points") |"
echo "| ray-cone, per point | $cone | $(per "$cone" "$points") |"
echo "| ray-ray, per point | $ray | $(per "$ray" "$points") |"
if [ -n "$json" ]; then
  cat >"$json.part" <<JSON
{"stripe_instructions_per_frame": $(per "$stripe" "$frames"),
 "ray_plane_instructions_per_point": $(per "$plane" "$points"),
 "ray_cone_instructions_per_point": $(per "$cone" "$points"),
 "ray_ray_instructions_per_point": $(per "$ray" "$points"),
 "frames": $frames, "points": $points}
JSON
  mv "$json.part" "$json"
fi
