#!/bin/sh
# Plays a bag into `uwscan ros inspect` with a ROS master of its own, as a vehicle would feed the
# node, and records what the node publishes. Runs inside the caller's private network namespace
# (CTest starts the ROS tests through cmake/run_in_netns.sh): the master and the nodes listen on
# 127.0.0.1 only. Every process started here is stopped by its pid before the script ends.
#   replay_dive.sh UWSCAN BAG OUT_DIR [rosbag play options --] [uwscan ros inspect options]
# Writes OUT_DIR/node.{db,tum,ply,json,log}, OUT_DIR/published.bag; exits with the node's status.
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
roscore -p 11311 >"$out/roscore.log" 2>&1 &
pids="$!"
waited=0
until rostopic list >/dev/null 2>&1; do
  sleep 0.2; waited=$((waited + 1))
  if [ $waited -gt 100 ]; then echo "replay_dive: roscore did not start (see $out/roscore.log)" >&2; exit 90; fi
done
rosbag record -O "$out/published.bag" /uwscan/path /uwscan/navigation_path /uwscan/map /uwscan/sweep \
  /uwscan/pose /tf __name:=uwscan_test_recorder >"$out/record.log" 2>&1 &
recorder=$!
pids="$recorder $pids"
"$uwscan" ros inspect --log "$out/node.db" --trajectory "$out/node.tum" -o "$out/node.ply" \
  --json "$out/node.json" "$@" >"$out/node.log" 2>&1 &
node=$!
# The node subscribes to the frames at once; play only when it (and the recorder) listen.
waited=0
until rostopic info /uwscan/frames 2>/dev/null | grep -q uwscan_inspection &&
      rostopic info /uwscan/path 2>/dev/null | grep -q uwscan_test_recorder; do
  sleep 0.2; waited=$((waited + 1))
  if [ $waited -gt 150 ]; then echo "replay_dive: the node did not subscribe (see $out/node.log)" >&2; kill -INT $node; exit 91; fi
done
# shellcheck disable=SC2086
rosbag play --quiet $play_options "$bag" >"$out/play.log" 2>&1
wait $node
status=$?
sleep 1  # the recorder writes what the node published last
exit $status
