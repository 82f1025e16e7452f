#!/bin/sh
# Plays a bag into `uwscan ros inspect` with a ROS master of its own, as a vehicle would feed the
# node, and records what the node publishes. Runs inside the caller's private network namespace
# (CTest starts the ROS tests through cmake/run_in_netns.sh): the master and the nodes listen on
# 127.0.0.1 only. Every process started here is stopped by its pid before the script ends.
#   replay_dive.sh UWSCAN BAG OUT_DIR [rosbag play options --] [uwscan ros inspect options]
# Writes OUT_DIR/node.{db,tum,ply,json,log}, OUT_DIR/published.bag; exits with the node's status.
# Faults, from the environment: MASTER_DOWN_AT=S kills the master S seconds into the replay and
# starts a new one 2 s later; SIGINT_AT=S sends the node SIGINT S seconds into the replay.
# RECOGNIZE_DB=DB also runs `uwscan ros recognize --db DB` on the node's sweeps (its figures in
# OUT_DIR/recognition.json, its output in OUT_DIR/recognition.log).
set -u
uwscan=$1 bag=$2 out=$3
shift 3
play_options=""
case " $* " in
  *" -- "*)
    while [ "$1" != "--" ]; do play_options="$play_options $1"; shift; done
    shift ;;
esac
mkdir -p "$out/ros_home/log"
export ROS_MASTER_URI=http://127.0.0.1:11311 ROS_IP=127.0.0.1 ROS_HOME="$out/ros_home" ROS_LOG_DIR="$out/ros_home/log"
pids=""
cleanup() {
  for pid in $pids; do kill -INT "$pid" 2>/dev/null; done
  for pid in $pids; do wait "$pid" 2>/dev/null; done
}
trap cleanup EXIT
start_master() {
  roscore -p 11311 >>"$out/roscore.log" 2>&1 &
  master=$!
  pids="$master $pids"
  waited=0
  until rostopic list >/dev/null 2>&1; do
    sleep 0.2; waited=$((waited + 1))
    if [ $waited -gt 100 ]; then echo "replay_dive: roscore did not start (see $out/roscore.log)" >&2; exit 90; fi
  done
}
start_master
rosbag record -O "$out/published.bag" /uwscan/path /uwscan/navigation_path /uwscan/map /uwscan/sweep \
  /uwscan/pose /tf /uwscan/objects /uwscan/object_poses /uwscan/grasps __name:=uwscan_test_recorder \
  >"$out/record.log" 2>&1 &
recorder=$!
pids="$recorder $pids"
"$uwscan" ros inspect --log "$out/node.db" --trajectory "$out/node.tum" -o "$out/node.ply" \
  --json "$out/node.json" "$@" >"$out/node.log" 2>&1 &
node=$!
recognizer=""
if [ -n "${RECOGNIZE_DB:-}" ]; then
  "$uwscan" ros recognize --db "$RECOGNIZE_DB" --idle-stop-s 20 --json "$out/recognition.json" \
    >"$out/recognition.log" 2>&1 &
  recognizer=$!
  waited=0
  until rostopic info /uwscan/sweep 2>/dev/null | grep -q uwscan_recognition; do
    sleep 0.2; waited=$((waited + 1))
    if [ $waited -gt 150 ]; then echo "replay_dive: the recognizer did not subscribe" >&2; exit 92; fi
  done
fi
# The node subscribes to the frames at once; play only when it (and the recorder) listen.
waited=0
until rostopic info /uwscan/frames 2>/dev/null | grep -q uwscan_inspection &&
      rostopic info /uwscan/path 2>/dev/null | grep -q uwscan_test_recorder; do
  sleep 0.2; waited=$((waited + 1))
  if [ $waited -gt 150 ]; then echo "replay_dive: the node did not subscribe (see $out/node.log)" >&2; kill -INT $node; exit 91; fi
done
# shellcheck disable=SC2086
# -d 1: rosbag play waits after advertising, so that the node has connected before the first frame.
rosbag play --quiet -d 1 $play_options "$bag" >"$out/play.log" 2>&1 &
player=$!
pids="$player $pids"
if [ -n "${MASTER_DOWN_AT:-}" ]; then
  sleep "$MASTER_DOWN_AT"
  kill -INT "$master"; wait "$master"
  sleep 2
  start_master
fi
if [ -n "${SIGINT_AT:-}" ]; then
  sleep "$SIGINT_AT"
  kill -INT "$node"
fi
# The node ends on its own (idle after the last frame, SIGINT, or an error): the player, if still
# playing, is stopped then.
wait $node
status=$?
kill -INT $player 2>/dev/null
wait $player
if [ -n "$recognizer" ]; then
  wait "$recognizer" || status=$?
fi
sleep 1  # the recorder writes what the node published last
exit $status
