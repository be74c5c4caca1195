#!/usr/bin/env python3
"""Writes a ROS1 bag of a stereo image sequence (rcm simulate's left/ and
right/ folders) for the node's test: sensor_msgs/Image mono8 on
/stereo/left/image_raw and /stereo/right/image_raw, both stamped
t0 + k / rate [s], k = 0, 1, ...

usage: write_stereo_bag.py SIM_DIR OUT.bag [--rate HZ] [--right-offset S]
                           [--bad mono16|small|black|left-only] [--t0 S]
                           [--frames FIRST:END]
--right-offset shifts the right stamps (pairs that never sync); --bad
writes bad input instead: 16-bit images (an encoding the node refuses),
images of half the calibration's size, black frames, or left images only
(a camera that stopped). --frames writes the frames FIRST, ..., END - 1
only, the first of them at t0.
"""
import numpy as np
import argparse
import os
import sys

import cv2
import rosbag
import rospy
from sensor_msgs.msg import Image


def image_message(gray, stamp, frame_id):
    message = Image()
    message.header.stamp = stamp
    message.header.frame_id = frame_id
    message.height, message.width = gray.shape
    message.encoding = "mono8"
    message.is_bigendian = 0
    message.step = message.width
    message.data = gray.tobytes()
    return message


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sim_dir")
    parser.add_argument("out")
    parser.add_argument("--rate", type=float, default=10.0)
    parser.add_argument("--right-offset", type=float, default=0.0)
    parser.add_argument("--bad", choices=["mono16", "small", "black", "left-only"])
    parser.add_argument("--t0", type=float, default=1000.0)
    parser.add_argument("--frames", default=None)
    args = parser.parse_args()
    names = sorted(os.listdir(os.path.join(args.sim_dir, "left")))
    if args.frames:
        first, end = (int(v) for v in args.frames.split(":"))
        names = names[first:end]
    if not names:
        sys.exit("write_stereo_bag.py: no images in %s/left" % args.sim_dir)
    t0 = args.t0
    with rosbag.Bag(args.out, "w") as bag:
        for k, name in enumerate(names):
            images = []
            for side in ("left", "right"):
                path = os.path.join(args.sim_dir, side, name)
                gray = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
                if gray is None:
                    sys.exit("write_stereo_bag.py: cannot read " + path)
                images.append(gray)
            t_left = rospy.Time.from_sec(t0 + k / args.rate)
            t_right = rospy.Time.from_sec(t0 + k / args.rate + args.right_offset)
            messages = [image_message(images[0], t_left, "cam0"),
                        image_message(images[1], t_right, "cam1")]
            for m, gray in zip(messages, images):
                if args.bad == "mono16":
                    m.encoding = "mono16"
                    m.step = 2 * m.width
                    m.data = (gray.astype(np.uint16) * 256).tobytes()
                elif args.bad == "small":
                    small = cv2.resize(gray, (m.width // 2, m.height // 2))
                    m.height, m.width = small.shape
                    m.step = m.width
                    m.data = small.tobytes()
                elif args.bad == "black":
                    m.data = bytes(len(m.data))
            bag.write("/stereo/left/image_raw", messages[0], t_left)
            if args.bad != "left-only":
                bag.write("/stereo/right/image_raw", messages[1], t_right)
    print("wrote %s: %d pairs" % (args.out, len(names)))


if __name__ == "__main__":
    main()
