#!/usr/bin/env bash
# Regenerates the README's pictures in docs/ with the program itself (run from anywhere; needs a
# build: ./run build). Without an X display it runs under Xvfb (cmake/run_with_display.sh).
#   scripts/make_docs_pictures.sh [UWSCAN_BINARY]
set -euo pipefail
cd "$(dirname "$0")/.."
UWSCAN=${1:-build/bin/uwscan}
[ -x "$UWSCAN" ] || { echo "make_docs_pictures: no $UWSCAN (./run build first)" >&2; exit 1; }
if [ -z "${UWSCAN_DOCS_UNDER_DISPLAY:-}" ]; then
  export UWSCAN_DOCS_UNDER_DISPLAY=1
  exec cmake/run_with_display.sh "$0" "$UWSCAN"
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p docs

# The demo scene, reconstructed with the galvanometer's default ray-cone, coloured by error.
"$UWSCAN" simulate data/scenes/default.yaml -o "$work/dive.db" >/dev/null
"$UWSCAN" view "$work/dive.db" --colour error --screenshot docs/demo_error.png --size 1280x800
"$UWSCAN" view "$work/dive.db" --edl --point-size 3 --camera top --screenshot docs/demo_edl_top.png --size 1280x800

# Recognition on the demo scene, as the README's quick start runs it: the valve taught from a
# scan of it, each recognised model drawn where it was found, with its label and grasp frame.
"$UWSCAN" make-object valve --handle lever --points 50000 -o "$work/valve_scan.ply" >/dev/null
"$UWSCAN" build-db "$work/valve_scan.ply" flange pipe --views 16 -o "$work/objects.db" >/dev/null
"$UWSCAN" recognize "$work/dive.db" --db "$work/objects.db" --json "$work/recognition.json" >/dev/null
"$UWSCAN" view "$work/recognition.json" --screenshot docs/recognition_demo.png --size 1280x800

# A map of the short inspection dive: SLAM (blue), dead reckoning (orange) and truth (green)
# over the SLAM map, with 3-sigma position ellipsoids.
"$UWSCAN" simulate data/scenes/inspection_short.yaml -o "$work/inspection.db" >/dev/null
"$UWSCAN" map "$work/inspection.db" -o "$work/map.ply" --json "$work/map.json" >/dev/null
"$UWSCAN" view "$work/map.json" --camera top --ellipsoid-every 2 --screenshot docs/map_inspection_short.png \
  --size 1280x800

# The looping dive's SLAM map from above, coloured by its distance to the scene's true surfaces
# (bench/slam/RESULTS.md, "What limits it"): the error sits on the faces that look along the track.
"$UWSCAN" simulate data/scenes/inspection_loop.yaml -o "$work/loop.db" >/dev/null
"$UWSCAN" map "$work/loop.db" -o "$work/loop.ply" >/dev/null
"$UWSCAN" view "$work/loop.ply" --scene data/scenes/inspection_loop.yaml --camera top --range 0 0.01 --point-size 1 \
  --screenshot docs/map_inspection_loop_error.png --size 560x1280

# Trade-offs: triangulation methods (and their tables' resolutions) and stripe detectors,
# accuracy against time.
"$UWSCAN" bench triangulation --points 1000000 --sweep-grid-px 1 2 4 8 16 --sweep-rays-per-fan 9 17 35 70 \
  --json "$work/triangulation.json" >/dev/null
"$UWSCAN" plot "$work/triangulation.json" -o docs/triangulation_tradeoff.png
"$UWSCAN" bench stripe --json "$work/stripe.json" >/dev/null
"$UWSCAN" plot "$work/stripe.json" -o docs/stripe_tradeoff.png
echo "make_docs_pictures: docs/*.png written"

# What the inspection found: two surveys of the change scenes mapped by SLAM, the second against
# the first; significant deviations in the diverging colours, the largest regions labelled.
"$UWSCAN" simulate data/scenes/change_before.yaml -o "$work/before.db" >/dev/null
"$UWSCAN" simulate data/scenes/change_after.yaml -o "$work/after.db" >/dev/null
"$UWSCAN" compare "$work/after.db" --reference "$work/before.db" -o "$work/changes.ply" \
  --json "$work/changes.json" >/dev/null
"$UWSCAN" view "$work/changes.json" --camera top --range -0.02 0.02 --screenshot docs/findings.png --size 800x900
