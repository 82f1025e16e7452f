#!/usr/bin/python3
"""Rewrites a bag uwscan exported as a vehicle's own recorder would have written it, for the
import tests: no dive description; the frames on the vehicle's camera topic, recorded 5 ms after
their stamp; the odometry on the navigator's topic with the vehicle's frame names, recorded 20 ms
after its stamp (so frames and navigation interleave out of stamp order); odom -> base_link on
/tf at 50 Hz (held from the latest odometry); the camera's mount as a chain of two static
transforms (base_link -> mast -> camera); and other topics the importer must leave alone (a
colour camera, a string log). Uses ROS's own Python bag library.
    vehicle_bag.py IN.bag OUT.bag"""
import sys

import rosbag
import rospy
from geometry_msgs.msg import TransformStamped
from sensor_msgs.msg import Image
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

PREFIX = "/girona500"
BASE = "girona500/base_link"
MAST = "girona500/mast"
CAMERA = "girona500/laser_camera"


def mast_chain(mount, stamp):
    """base_link -> mast (a pure offset) and mast -> camera, composing to `mount`."""
    first = TransformStamped()
    first.header.stamp = stamp
    first.header.frame_id = BASE
    first.child_frame_id = MAST
    first.transform.translation.x = 0.1
    first.transform.rotation.w = 1.0
    second = TransformStamped()
    second.header.stamp = stamp
    second.header.frame_id = MAST
    second.child_frame_id = CAMERA
    second.transform.translation.x = mount.transform.translation.x - 0.1
    second.transform.translation.y = mount.transform.translation.y
    second.transform.translation.z = mount.transform.translation.z
    second.transform.rotation = mount.transform.rotation
    return TFMessage(transforms=[first, second])


def main():
    source, target = sys.argv[1], sys.argv[2]
    out = rosbag.Bag(target, "w")
    last_odometry = None
    next_tf = None
    frames = 0
    for topic, message, t in rosbag.Bag(source).read_messages():
        if topic == "/uwscan/dive":
            continue
        if topic == "/tf_static":
            out.write("/tf_static", mast_chain(message.transforms[0], message.transforms[0].header.stamp), t)
            continue
        if topic == "/uwscan/frames":
            message.header.frame_id = CAMERA
            arrival = message.header.stamp + rospy.Duration(0.005)
            out.write(PREFIX + "/camera/profile", message, arrival)
            frames += 1
            if frames % 10 == 0:
                colour = Image(header=message.header, height=2, width=2, encoding="rgb8", step=6, data=bytes(12))
                out.write(PREFIX + "/camera/colour", colour, arrival)
            continue
        if topic == "/navigation/odometry":
            message.header.frame_id = "world_ned"
            message.child_frame_id = BASE
            out.write(PREFIX + "/navigator/odometry", message, message.header.stamp + rospy.Duration(0.020))
            last_odometry = message
            if next_tf is None:
                next_tf = message.header.stamp
            while next_tf <= message.header.stamp:
                tf = TransformStamped()
                tf.header.stamp = next_tf
                tf.header.frame_id = "world_ned"
                tf.child_frame_id = BASE
                tf.transform.translation.x = last_odometry.pose.pose.position.x
                tf.transform.translation.y = last_odometry.pose.pose.position.y
                tf.transform.translation.z = last_odometry.pose.pose.position.z
                tf.transform.rotation = last_odometry.pose.pose.orientation
                out.write("/tf", TFMessage(transforms=[tf]), next_tf)
                out.write(PREFIX + "/status", String(data="navigator alive"), next_tf)
                next_tf += rospy.Duration(0.02)
            continue
    out.close()


if __name__ == "__main__":
    main()
