#!/usr/bin/env bash
# The installed program finds its data wherever it runs from: `cmake --install` into a temporary
# prefix, then, from an empty folder with UWSCAN_DATA_DIR unset, commands that read the shipped
# scenes and scanners by default must find PREFIX/share/uwscan (not the source tree's data/,
# which the program also knows: the outputs must name the installed folder).
#   tests/install_test.sh CMAKE BUILD_DIR     (the CTest test install_test)
set -euo pipefail
cmake=$1
build=$(cd "$2" && pwd)

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix
fail() { echo "install_test: $*" >&2; exit 1; }

"$cmake" --install "$build" --prefix "$prefix" >/dev/null
uwscan=$prefix/bin/uwscan
data=$prefix/share/uwscan
for file in scanners/galvo_default.yaml scenes/default.yaml scenes/inspection_short.yaml \
  genicam/uwscan_fake_camera.xml rviz/uwscan.rviz; do
  [ -f "$data/$file" ] || fail "not installed: share/uwscan/$file"
done
for file in README.md docs/cli.md docs/commands.md docs/demo_error.png; do
  [ -f "$prefix/share/doc/uwscan/$file" ] || fail "not installed: share/doc/uwscan/$file"
done

unset UWSCAN_DATA_DIR
mkdir "$tmp/elsewhere"
cd "$tmp/elsewhere"

found=$("$uwscan" --data-dir) || fail "uwscan --data-dir failed"
[ "$found" = "$data" ] || fail "uwscan --data-dir printed '$found', expected '$data'"

# demo's default scene (and the scanner file the scene names relative to itself).
"$uwscan" demo >demo.txt 2>&1 || fail "demo failed: $(cat demo.txt)"
grep -qF "Scene $data/scenes/default.yaml: " demo.txt || fail "demo did not read the installed scene: $(cat demo.txt)"
grep -q "ray_ray" demo.txt || fail "demo printed no ray_ray row: $(cat demo.txt)"

# A bench's default data folder: copies the shipped scenes and scanners.
"$uwscan" bench robustness --write-seeds seeds >robustness.txt 2>&1 || fail "bench robustness failed: $(cat robustness.txt)"
[ -f seeds/scanner_yaml/seed_0.yaml ] || fail "bench robustness --write-seeds wrote no scanner seed"

# The quick starts' form: a shipped scene named through --data-dir.
"$uwscan" simulate "$("$uwscan" --data-dir)/scenes/default.yaml" -o demo.db >simulate.txt 2>&1 ||
  fail "simulate failed: $(cat simulate.txt)"

# UWSCAN_DATA_DIR comes first, and a wrong one is named.
[ "$(UWSCAN_DATA_DIR=seeds "$uwscan" --data-dir)" = seeds ] || fail "UWSCAN_DATA_DIR was not used"
if UWSCAN_DATA_DIR=missing "$uwscan" --data-dir >wrong.txt 2>&1; then fail "UWSCAN_DATA_DIR=missing was accepted"; fi
grep -q "UWSCAN_DATA_DIR=missing: not a folder" wrong.txt || fail "unexpected message: $(cat wrong.txt)"
echo "install_test: $uwscan found $data from $PWD"
