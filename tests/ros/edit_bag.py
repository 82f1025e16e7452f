#!/usr/bin/python3
"""Writes a copy of a bag uwscan exported with one fault in its frames, for the tests that
uwscan refuses it by name. Uses ROS's own Python bag library.
    edit_bag.py IN.bag OUT.bag stamp_back N     frame N stamped 1 s before the one before it
    edit_bag.py IN.bag OUT.bag encoding NAME    every frame's encoding set to NAME
    edit_bag.py IN.bag OUT.bag frames_until S   no frame from S s after the first on"""
import sys

import rosbag
import rospy


def main():
    source, target, fault, value = sys.argv[1:5]
    out = rosbag.Bag(target, "w")
    frame = 0
    first = None
    previous = None
    for topic, message, t in rosbag.Bag(source).read_messages(return_connection_header=False):
        if topic == "/uwscan/frames":
            first = first or message.header.stamp
            if fault == "stamp_back" and frame == int(value):
                message.header.stamp = previous - rospy.Duration(1.0)
            if fault == "encoding":
                message.encoding = value
            if fault == "frames_until" and (message.header.stamp - first).to_sec() >= float(value):
                continue
            previous = message.header.stamp
            frame += 1
        out.write(topic, message, t)
    out.close()


if __name__ == "__main__":
    main()
