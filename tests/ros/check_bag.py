#!/usr/bin/python3
"""Reads a bag with ROS's own Python reader (python3-rosbag), independently of uwscan's C++ one,
and prints one JSON line per topic: type, message count, first and last header stamp, frame ids
seen, whether header stamps never go back, and for some types what they hold (the last path's
positions, the last marker array's labels, every pose's position, the last cloud's point
count, fields and centroid (and the share of finite values of a "deviation" field) and the last
pose array's size). Used by tests/cli_ros_test.cpp."""
import json
import sys

import rosbag
from sensor_msgs import point_cloud2


def main():
    bag = rosbag.Bag(sys.argv[1])
    topics = {}
    last_clouds = {}
    for topic, message, _ in bag.read_messages():
        entry = topics.setdefault(topic, {"type": message._type, "count": 0, "frame_ids": [],
                                          "first_stamp": None, "last_stamp": None, "ordered": True,
                                          "children": []})
        entry["count"] += 1
        header = getattr(message, "header", None)
        if header is not None:
            stamp = header.stamp.to_sec()
            if entry["last_stamp"] is not None and stamp < entry["last_stamp"]:
                entry["ordered"] = False
            if entry["first_stamp"] is None:
                entry["first_stamp"] = stamp
            entry["last_stamp"] = stamp
            if header.frame_id not in entry["frame_ids"]:
                entry["frame_ids"].append(header.frame_id)
        for transform in getattr(message, "transforms", []):
            pair = transform.header.frame_id + " " + transform.child_frame_id
            if pair not in entry["children"]:
                entry["children"].append(pair)
        if hasattr(message, "child_frame_id") and message.child_frame_id not in entry["children"]:
            entry["children"].append(message.child_frame_id)
        if hasattr(message, "markers"):
            entry["last_labels"] = [m.text for m in message.markers if m.text]
        if message._type == "geometry_msgs/PoseWithCovarianceStamped":
            p = message.pose.pose.position
            entry.setdefault("positions", []).append([p.x, p.y, p.z])
        if message._type == "sensor_msgs/PointCloud2":
            entry["last_points"] = message.width * message.height
            entry["last_fields"] = [f.name for f in message.fields]
            last_clouds[topic] = message
            if "deviation" in entry["last_fields"]:
                values = [v[0] for v in point_cloud2.read_points(message, field_names=["deviation"])]
                finite = [v for v in values if v == v]
                entry["last_finite_share"] = len(finite) / max(1, len(values))
        if message._type == "geometry_msgs/PoseArray":
            entry["last_poses"] = len(message.poses)
        if topic.endswith("/path") and hasattr(message, "poses"):
            entry["last_path"] = [[p.header.stamp.to_sec(), p.pose.position.x, p.pose.position.y,
                                   p.pose.position.z] for p in message.poses]
    bag.close()
    for topic, message in last_clouds.items():
        xyz = list(point_cloud2.read_points(message, field_names=["x", "y", "z"]))
        topics[topic]["last_centroid"] = [sum(p[k] for p in xyz) / max(1, len(xyz))
                                          for k in range(3)]
    print(json.dumps(topics))


if __name__ == "__main__":
    main()
