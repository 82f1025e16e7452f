#!/bin/sh
# Draws docs/ros_rviz.png, the README's ROS picture: RViz (data/rviz/uwscan.rviz) near the end of
# a replay of the short inspection dive through `uwscan ros inspect`. Needs rviz, xvfb, x11-apps
# and netpbm (apt-get install rviz xvfb x11-apps netpbm) and root for a private network namespace
# (the master and nodes then reach nothing but each other). Run from the source tree after
# ./run build.
set -eu
cd "$(dirname "$0")/.."
if [ "${1:-}" != "--inside" ]; then
  exec unshare -n sh -c 'ip link set lo up && exec "$0" --inside' "$0"
fi
uwscan=$PWD/build/bin/uwscan
tmp=$(mktemp -d)
export ROS_MASTER_URI=http://127.0.0.1:11311 ROS_IP=127.0.0.1 ROS_HOME=$tmp/ros ROS_LOG_DIR=$tmp/ros/log DISPLAY=:97
mkdir -p "$ROS_LOG_DIR"
pids=""
trap 'for p in $pids; do kill -INT $p 2>/dev/null; done; wait; rm -rf "$tmp"' EXIT
"$uwscan" simulate data/scenes/inspection_short.yaml -o "$tmp/dive.db" >/dev/null
"$uwscan" bag export "$tmp/dive.db" -o "$tmp/dive.bag" >/dev/null
Xvfb :97 -screen 0 1400x900x24 >/dev/null 2>&1 & pids="$! $pids"
roscore >/dev/null 2>&1 & pids="$! $pids"
until rostopic list >/dev/null 2>&1; do sleep 0.2; done
"$uwscan" ros inspect --idle-stop-s 30 _map_period_s:=1.0 >"$tmp/node.log" 2>&1 & pids="$! $pids"
rviz -d data/rviz/uwscan.rviz >"$tmp/rviz.log" 2>&1 & pids="$! $pids"
until rostopic info /uwscan/frames 2>/dev/null | grep -q uwscan_inspection; do sleep 0.2; done
sleep 8  # RViz's first frames
rosbag play --quiet "$tmp/dive.bag" >/dev/null 2>&1
sleep 3
# The 3-D view only, without RViz's panels.
xwd -root -silent | xwdtopnm 2>/dev/null | pnmcut -left 366 -top 64 -width 1016 -height 800 | pnmtopng > docs/ros_rviz.png
echo "docs/ros_rviz.png: written"
