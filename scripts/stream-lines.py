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
"""
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


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("manifest")
    ap.add_argument("modules", help="comma-separated module names")
    ap.add_argument("--realtime", action="store_true", help="send each line when its time comes")
    ap.add_argument("--speed", type=float, default=1.0, help="with --realtime: this many times real time")
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
