#!/usr/bin/python3
"""Rewrites a bag uwscan exported as a vehicle following REP 103's default axes would have
recorded it: the navigation (nav_msgs/Odometry and odom -> base_link on /tf) in an ENU world with
a forward-left-up vehicle, and the camera's mount on /tf_static from that forward-left-up
base_link, for the tests that uwscan turns them back. Uses ROS's own Python bag library; the
turns are written out here as quaternions (no numpy), independently of uwscan's matrices.
    enu_bag.py IN.bag OUT.bag"""
import math
import sys

import rosbag

# Half turns: about (1, 1, 0)/sqrt(2) takes NED to ENU (and back); about x, FRD to FLU.
NED_ENU = (0.0, 1.0 / math.sqrt(2.0), 1.0 / math.sqrt(2.0), 0.0)  # w, x, y, z
FRD_FLU = (0.0, 1.0, 0.0, 0.0)


def multiply(a, b):
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw)


def turn_vehicle_pose(position, orientation):
    """T_ned_frd -> T_enu_flu: the world turned on the left, the vehicle on the right."""
    position.x, position.y, position.z = position.y, position.x, -position.z
    q = multiply(multiply(NED_ENU, (orientation.w, orientation.x, orientation.y, orientation.z)), FRD_FLU)
    orientation.w, orientation.x, orientation.y, orientation.z = q


def turn_mount(translation, rotation):
    """T_frd_camera -> T_flu_camera."""
    translation.y, translation.z = -translation.y, -translation.z
    q = multiply(FRD_FLU, (rotation.w, rotation.x, rotation.y, rotation.z))
    rotation.w, rotation.x, rotation.y, rotation.z = q


def main():
    source, target = sys.argv[1], sys.argv[2]
    out = rosbag.Bag(target, "w")
    for topic, message, t in rosbag.Bag(source).read_messages():
        if topic == "/navigation/odometry":
            turn_vehicle_pose(message.pose.pose.position, message.pose.pose.orientation)
        if topic == "/tf":
            for transform in message.transforms:
                if transform.header.frame_id == "odom" and transform.child_frame_id == "base_link":
                    turn_vehicle_pose(transform.transform.translation, transform.transform.rotation)
        if topic == "/tf_static":
            for transform in message.transforms:
                turn_mount(transform.transform.translation, transform.transform.rotation)
        out.write(topic, message, t)
    out.close()


if __name__ == "__main__":
    main()
