#!/usr/bin/env python3
"""Metric depth from Debian's stereo_image_proc on rcm_ros_node's rectified
output, against the simulator's truth.

usage: check_depth.py DEPTH.bag SIM_DIR --t0 S --rate HZ --first K
                      --frames A:B (--within F | --off-by-more-than F)

DEPTH.bag holds stereo_msgs/DisparityImage on .../disparity and the
node's sensor_msgs/CameraInfo on .../left/camera_info (rosbag record). The
disparity stamped t0 + j / rate is of simulated frame first + j; the
frames checked are A, ..., B - 1.

For a valid disparity d at rectified left pixel (u, v), stereo_image_proc's
depth is Z = f T / d (f, T of the DisparityImage) and its point in the
rectified left frame X = ((u - cx) Z / fx, (v - cy) Z / fy, Z), cx, cy, fx,
fy of the node's left camera_info of the same stamp. The node publishes R = I (its images are
the rectified ones), and the simulated rig (alphasense) is rectified in
air, so the rectified left frame is cam0's. The truth is the pool along the
same line of sight: from cam0's centre (truth.csv: world_from_cam0) through
X to the first wall, floor or surface of the box [0, length] x [0, width]
x [0, depth] (simulation.json, "tank"), a point at depth z_true along
cam0's axis. The port of `rcm simulate` has no air gap and no glass, so
the water bends every ray at the centre and a pinhole model is exact up to
the fit of the virtual camera: a right n gives the pool's depth, n = 1 a
depth short by about 1 / 1.333.

Per frame: the median of Z / z_true - 1 over its valid pixels. Checked:
with --within F every frame's |median| <= F; with --off-by-more-than F
every frame's |median| > F.
"""
import argparse
import csv
import json
import os
import sys

import numpy as np
import rosbag


def quaternion_matrix(qx, qy, qz, qw):
    x, y, z, w = qx, qy, qz, qw
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def ray_exit(origin, directions, box):
    """Distance along unit directions (N x 3) from origin inside the box
    [0, box] to the first face."""
    with np.errstate(divide="ignore", invalid="ignore"):
        hi = (box[None, :] - origin[None, :]) / directions
        lo = (0.0 - origin[None, :]) / directions
    t = np.where(directions > 0, hi, np.where(directions < 0, lo, np.inf))
    return t.min(axis=1)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("bag")
    parser.add_argument("sim_dir")
    parser.add_argument("--t0", type=float, required=True)
    parser.add_argument("--rate", type=float, required=True)
    parser.add_argument("--first", type=int, required=True)
    parser.add_argument("--frames", required=True)
    parser.add_argument("--label", default="")
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument("--within", type=float)
    group.add_argument("--off-by-more-than", type=float)
    args = parser.parse_args()
    begin, end = (int(v) for v in args.frames.split(":"))

    settings = json.load(open(os.path.join(args.sim_dir, "simulation.json")))
    box = np.array([settings["tank"]["length"], settings["tank"]["width"],
                    settings["tank"]["depth"]])
    poses = {}
    for row in csv.DictReader(open(os.path.join(args.sim_dir, "truth.csv"))):
        poses[int(row["frame"])] = (
            quaternion_matrix(*(float(row[k]) for k in ("qx", "qy", "qz", "qw"))),
            np.array([float(row[k]) for k in ("tx", "ty", "tz")]),
            float(row["n"]))

    # The camera model changes with n: each disparity with the left
    # camera_info of its own stamp.
    infos = {}
    disparities = {}
    with rosbag.Bag(args.bag) as bag:
        for topic, message, _ in bag.read_messages():
            j = round((message.header.stamp.to_sec() - args.t0) * args.rate)
            if topic.endswith("left/camera_info"):
                infos[args.first + j] = message
            elif topic.endswith("disparity"):
                disparities[args.first + j] = message

    medians = []
    for k in range(begin, end):
        message = disparities.get(k)
        info = infos.get(k)
        if message is None or info is None:
            sys.exit("check_depth: no disparity or camera_info of frame %d "
                     "(disparities of %s)" % (k, sorted(disparities)))
        if list(info.R) != [1, 0, 0, 0, 1, 0, 0, 0, 1]:
            sys.exit("check_depth: the node's R is not the identity: %s"
                     % (info.R,))
        fx, fy, cx, cy = info.P[0], info.P[5], info.P[2], info.P[6]
        image = message.image
        d = np.frombuffer(image.data, dtype=np.float32).reshape(
            image.height, image.width)
        valid = np.isfinite(d) & (d > message.min_disparity) & (
            d <= message.max_disparity)
        v, u = np.nonzero(valid)
        if len(u) < 0.05 * d.size:
            sys.exit("check_depth: frame %d: %d valid disparities of %d"
                     % (k, len(u), d.size))
        z = message.f * message.T / d[valid]
        rays = np.stack([(u - cx) / fx, (v - cy) / fy, np.ones_like(z)], axis=1)
        rotation, centre, n = poses[k]
        directions = rays @ rotation.T
        directions /= np.linalg.norm(directions, axis=1, keepdims=True)
        distance = ray_exit(centre, directions, box)
        # Depth along cam0's axis of the pool's point on that line of sight.
        z_true = distance * (directions @ rotation[:, 2])
        error = z / z_true - 1.0
        median = float(np.median(error))
        medians.append(median)
        print("check_depth: %sframe %2d (n %.3f): %6d pixels, depth %.2f-%.2f m, "
              "median error %+.4f, quartiles %+.4f %+.4f"
              % (args.label, k, n, len(u), np.percentile(z_true, 5),
                 np.percentile(z_true, 95), median,
                 np.percentile(error, 25), np.percentile(error, 75)))
    worst = max(medians, key=abs)
    best = min(medians, key=abs)
    if args.within is not None:
        print("check_depth: %sworst median depth error %+.4f (limit %.3f)"
              % (args.label, worst, args.within))
        if abs(worst) > args.within:
            sys.exit("check_depth: median depth error %+.4f, more than %.3f"
                     % (worst, args.within))
    else:
        print("check_depth: %ssmallest median depth error %+.4f (must exceed %.3f)"
              % (args.label, best, args.off_by_more_than))
        if abs(best) <= args.off_by_more_than:
            sys.exit("check_depth: median depth error %+.4f, not more than %.3f"
                     % (best, args.off_by_more_than))


if __name__ == "__main__":
    main()
