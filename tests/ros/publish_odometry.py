#!/usr/bin/python3
"""Publishes a still vehicle's odometry (identity pose) stamped 0, 0.05, ... up to SECONDS s of
the dive's clock, as fast as the node takes it, once the node listens: the navigation for a
simulated camera, whose frames carry the dive's clock. Uses ROS's own Python client.
    publish_odometry.py SECONDS"""
import sys

import rospy
from nav_msgs.msg import Odometry


def main():
    seconds = float(sys.argv[1])
    rospy.init_node("uwscan_test_navigation", anonymous=True)
    publisher = rospy.Publisher("/navigation/odometry", Odometry, queue_size=100000)
    while publisher.get_num_connections() == 0 and not rospy.is_shutdown():
        rospy.sleep(0.1)
    rospy.sleep(0.5)
    for i in range(int(seconds / 0.05) + 1):
        message = Odometry()
        message.header.stamp = rospy.Time.from_sec(i * 0.05)
        message.header.frame_id = "odom"
        message.child_frame_id = "base_link"
        message.pose.pose.orientation.w = 1.0
        publisher.publish(message)
    rospy.sleep(2.0)


if __name__ == "__main__":
    main()
