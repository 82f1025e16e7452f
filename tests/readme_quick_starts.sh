#!/usr/bin/env bash
# Runs every command of README.md's "Set up" PATH block and of its "Quick starts" blocks, in
# order, as a reader pasting them would, in an empty folder: the front page cannot rot. CTest runs
# it inside a private network namespace (the fake camera and the ROS master stay on this machine)
# with an X display (cmake/run_with_display.sh).
#   tests/readme_quick_starts.sh BUILD_BIN_DIR
# What is changed so that nothing waits for a person, and nothing else:
#   - `uwscan inspect ... --view` runs for 4 s and writes its live view to a PNG instead;
#   - `uwscan view ...` writes its picture to a PNG and exits (--screenshot);
#   - `rviz` runs when it is installed (./run does not install it) and is stopped at the end;
#   - a program started in the background gets 2 s before the next line, as a person pasting
#     gives it; the blocks' background uwscan jobs are waited for (the ROS node ends 3 s after the
#     replay), then the rest (roscore, rviz) are stopped;
#   - ROS_IP is 127.0.0.1 and ROS_HOME a temporary folder.
# Fails on the first command that fails, naming it; every process started is stopped by its pid.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bin=$1
work=$(mktemp -d /tmp/uwscan_quick_starts.XXXXXX)
pictures=0
trap 'status=$?; for pid in $(jobs -p); do kill -INT "$pid" 2>/dev/null || true; done; wait 2>/dev/null; rm -rf "$work"; exit $status' EXIT
export ROS_IP=127.0.0.1 ROS_HOME="$work/ros_home" ROS_LOG_DIR="$work/ros_home/log"
mkdir -p "$ROS_LOG_DIR"

# The lines of the fenced blocks between two headings of README.md.
blocks_between() {
  awk -v from="$1" -v to="$2" '
    index($0, from) == 1 { inside = 1; next }
    index($0, to) == 1 { inside = 0 }
    inside && /^```/ { fence = !fence; if (!fence) print "#END_OF_BLOCK"; next }
    inside && fence { print }' "$root/README.md"
}

# One command line, made to end on its own (see the header).
adapt() {
  local line=$1
  # A trailing comment would swallow what is appended (the README's comments hold no quotes).
  [[ $line =~ ^(.*[^[:space:]])[[:space:]]+#[^\"\']*$ ]] && line=${BASH_REMATCH[1]}
  case "$line" in
    "uwscan inspect "*"--view"*)
      line=${line/--view/--seconds 4 --screenshot $work/inspect_view.png} ;;
    "uwscan view "*)
      pictures=$((pictures + 1))
      line="$line --screenshot $work/view_$pictures.png" ;;
    "rviz "*)
      command -v rviz >/dev/null || line="echo 'quick starts: rviz is not installed, not run' &${line#*&}" ;;
  esac
  printf '%s\n' "$line"
  # A program started in the background gets the moment a person pasting would give it.
  if [[ $line =~ \&[[:space:]]*(#.*)?$ ]]; then printf 'sleep 2\n'; fi
}

# A block in a shell of its own, reading nothing (rosbag play would take the rest of this
# script's input as keystrokes); its output in a file, shown when it fails.
run_block() {
  local script=$1
  echo "--- quick start block:"
  grep -v '^for pid\|^  for _\|^done$\|^sleep 2$' "$script" | sed 's/^/    /'
  if ! bash -euo pipefail "$script" </dev/null >"$script.log" 2>&1; then
    tail -n 60 "$script.log" | tr '\r' '\n' | tail -n 60 >&2
    echo "quick starts: this block failed (its output above)" >&2
    exit 1
  fi
}

# Set up: the PATH and DATA lines, as written (run from the source folder, as the README says).
setup=$(blocks_between "## Set up" "## Quick starts" | grep -E '^(export PATH=|DATA=)' | sed 's/ *#.*$//')
[ "$(printf '%s\n' "$setup" | wc -l)" = 2 ] || { echo "quick starts: the set-up's PATH and DATA lines are not in README.md" >&2; exit 1; }
cd "$root"
export PATH="$bin:$PATH"
eval "$setup"
export DATA PATH
[ "$(command -v uwscan)" = "$bin/uwscan" ] || { echo "quick starts: the README's PATH line does not find $bin/uwscan" >&2; exit 1; }
cd "$work"

# Each block runs in a shell of its own, in the same folder, so later blocks use earlier ones'
# files (the ROS block replays the dive the mapping block simulated).
count=0
script="$work/block_$count.sh"
: >"$script"
while IFS= read -r line; do
  if [ "$line" = "#END_OF_BLOCK" ]; then
    # Background jobs of the block are waited for, then stopped (the camera, roscore, rviz).
    printf '%s\n' 'for pid in $(jobs -p); do
  for _ in $(seq 1 60); do kill -0 "$pid" 2>/dev/null || break; case "$(ps -o comm= -p "$pid")" in uwscan) sleep 1;; *) break;; esac; done
done
for pid in $(jobs -p); do kill -INT "$pid" 2>/dev/null || true; done; wait || true' >>"$script"
    run_block "$script"
    count=$((count + 1))
    script="$work/block_$count.sh"
    : >"$script"
    continue
  fi
  adapt "$line" >>"$script"
done < <(blocks_between "## Quick starts" "## Documentation")
[ "$count" -ge 6 ] || { echo "quick starts: $count blocks found in README.md, expected 6" >&2; exit 1; }

# What the blocks were to make, there.
for f in inspect.db inspect_view.png objects.db recognition.json inspection.db map.ply map.json \
         as_built.ply before.db after.db changes.ply changes.json changes.md \
         inspection.bag node.db node.ply step1.yaml step2.yaml; do
  [ -s "$f" ] || { echo "quick starts: $f was not written" >&2; exit 1; }
done
for i in $(seq 1 "$pictures"); do
  [ -s "view_$i.png" ] || { echo "quick starts: view_$i.png was not written" >&2; exit 1; }
done
echo "quick starts: $count blocks ran; every file they make is there ($pictures pictures from view)"
