#!/bin/sh
# `uwscan ros inspect --camera` on the GigE Vision fake camera serving a scene, with a ROS master
# of its own and the vehicle's odometry from tests/ros/publish_odometry.py. Runs inside the
# caller's private network namespace (cmake/run_in_netns.sh); every process started here is
# stopped by its pid.
#   camera_node.sh UWSCAN SCENE OUT_DIR FRAMES
set -u
uwscan=$1 scene=$2 out=$3 frames=$4
here=$(dirname "$0")
mkdir -p "$out/ros_home/log"
export ROS_MASTER_URI=http://127.0.0.1:11311 ROS_IP=127.0.0.1 ROS_HOME="$out/ros_home" ROS_LOG_DIR="$out/ros_home/log"
pids=""
trap 'for pid in $pids; do kill -INT "$pid" 2>/dev/null; done; for pid in $pids; do wait "$pid" 2>/dev/null; done' EXIT
roscore -p 11311 >"$out/roscore.log" 2>&1 &
pids="$!"
waited=0
until rostopic list >/dev/null 2>&1; do
  sleep 0.2; waited=$((waited + 1))
  if [ $waited -gt 100 ]; then echo "camera_node: roscore did not start" >&2; exit 90; fi
done
"$uwscan" fake-camera "$scene" >"$out/camera.log" 2>&1 &
pids="$! $pids"
sleep 1
/usr/bin/python3 "$here/publish_odometry.py" 120 >"$out/odometry.log" 2>&1 &
pids="$! $pids"
"$uwscan" ros inspect --camera 127.0.0.1 --scene "$scene" --log "$out/node.db" --json "$out/node.json" \
  --frames "$frames" >"$out/node.log" 2>&1
