#!/usr/bin/env python3
"""A dataset's IMU records as the lines `wheelins live` reads (docs/live.md), in time order.

    scripts/stream-lines.py MANIFEST MODULE[,MODULE...] [--realtime [--speed X]] | \
        build/wheelins live -m MANIFEST --modules MODULE,...

Each record of the named modules' files becomes `module,t,gx,gy,gz,ax,ay,az` at full precision
(the file's values; the module's time_offset_s orders them, as a run merges its files; ties in
the order the modules are named). --realtime sends each line when its time comes, measured
from the first (--speed 2: twice as fast): a recording replayed as a live source. Reads the
binary 7-column files (`layout: binary`, as `wheelins simulate` and `wheelins import` write
them); other layouts are refused with the module's name.

    scripts/stream-lines.py MANIFEST MODULE[,MODULE...] --bag OUT.bag [--stop MODULE=T]

writes the same records as a ROS 1 bag instead (Debian's python3-rosbag), for
`rosbag play` into `wheelins live --ros`: one sensor_msgs/Imu topic per module, `NAME/imu`
with the name made a ROS name (characters other than letters, digits and _ become _), the
frame id the module's name, header.stamp the record's time (with its time_offset_s), the
bag's time 1 s later (a bag's time cannot be 0). --stop MODULE=T ends a module's records at
T s: a sensor that stops.
"""
import re
import argparse
import heapq
import os
import struct
import sys
import time

import yaml


def records(manifest_dir, spec):
    layout = spec.get("layout", "binary")
    if layout != "binary":
        sys.exit(f"stream-lines: module '{spec['name']}': layout '{layout}' is not read here (binary only)")
    path = os.path.join(manifest_dir, spec["file"])
    with open(path, "rb") as f:
        data = f.read()
    if len(data) % 56:
        sys.exit(f"stream-lines: '{path}': {len(data)} bytes is not a whole number of 7-double records")
    offset = float(spec.get("time_offset_s", 0.0))
    for k in range(len(data) // 56):
        row = struct.unpack_from("<7d", data, 56 * k)
        yield row[0] + offset, row


def ros_name(name):
    """A module's name as a ROS graph name (wheelins live --ros's default topic NAME/imu)."""
    n = re.sub(r"[^A-Za-z0-9_]", "_", name)
    return n if n[:1].isalpha() else "m" + n


def stops(items, names):
    out = {}
    for item in items:
        name, _, t = item.partition("=")
        if name not in names or not t:
            sys.exit(f"stream-lines: --stop '{item}': MODULE=T with MODULE one of {', '.join(names)}")
        out[names.index(name)] = float(t)
    return out


def stamp(rospy, t):
    """The ROS time nearest to t (rospy.Time.from_sec truncates to the nanosecond below: a
    time of 0.015 s could come back as 0.014999999)."""
    ns = round(t * 1e9) if t < 9e6 else int(t) * 1000000000 + round((t - int(t)) * 1e9)
    return rospy.Time(ns // 1000000000, ns % 1000000000)


def write_bag(path, names, merged, stop):
    import rosbag
    import rospy
    from sensor_msgs.msg import Imu

    topics = [ros_name(n) + "/imu" for n in names]
    seq = [0] * len(names)
    with rosbag.Bag(path, "w") as bag:
        for key, i, row in merged:
            if i in stop and key > stop[i]:
                continue
            m = Imu()
            m.header.seq = seq[i]
            seq[i] += 1
            m.header.stamp = stamp(rospy, key)
            m.header.frame_id = names[i]
            m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z = row[1:4]
            m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z = row[4:7]
            m.orientation_covariance[0] = -1.0  # no orientation
            bag.write("/" + topics[i], m, rospy.Time.from_sec(key + 1.0))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("manifest")
    ap.add_argument("modules", help="comma-separated module names")
    ap.add_argument("--realtime", action="store_true", help="send each line when its time comes")
    ap.add_argument("--speed", type=float, default=1.0, help="with --realtime: this many times real time")
    ap.add_argument("--bag", help="write a ROS 1 bag of sensor_msgs/Imu messages to this file instead")
    ap.add_argument("--stop", action="append", default=[], metavar="MODULE=T",
                    help="with --bag: the module's records end at T s")
    a = ap.parse_args()
    if not a.speed > 0:
        sys.exit("stream-lines: --speed must be positive")
    with open(a.manifest) as f:
        manifest = yaml.safe_load(f)
    specs = {m["name"]: m for m in manifest.get("modules", [])}
    names = [n for n in a.modules.split(",") if n]
    for n in names:
        if n not in specs:
            sys.exit(f"stream-lines: module '{n}' is not in '{a.manifest}' (modules: {', '.join(specs)})")
    base = os.path.dirname(os.path.abspath(a.manifest))
    def tagged(i, spec):
        for key, row in records(base, spec):
            yield key, i, row

    streams = [tagged(i, specs[n]) for i, n in enumerate(names)]
    if a.bag:
        write_bag(a.bag, names, heapq.merge(*streams), stops(a.stop, names))
        return
    out = sys.stdout
    start_key = start_wall = None
    try:
        for key, i, row in heapq.merge(*streams):
            if a.realtime:
                if start_key is None:
                    start_key, start_wall = key, time.monotonic()
                wait = start_wall + (key - start_key) / a.speed - time.monotonic()
                if wait > 0.0005:
                    out.flush()
                    time.sleep(wait)
            out.write(names[i] + "," + ",".join(repr(v) for v in row) + "\n")
        out.flush()
    except BrokenPipeError:
        sys.exit(0)  # the reader ended (e.g. its --duration)


if __name__ == "__main__":
    main()
