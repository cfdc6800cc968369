#!/usr/bin/env python3
"""Paired drift ratios of a study (docs/studies.md): for each pair A:B, the drift rate of B
over that of A on the same data (same condition and seed), per condition and over all:
how many pairs are "no worse" (ratio <= --bound, default 1.05), the geometric mean of the
ratios, the worst and the best. A or B may be min(X,Y,...): per data set the lowest drift of those
configurations (e.g. "the best three-IMU configuration"). A:B+C:D pools the ratios of several
pairs (e.g. each front wheel against the rear wheel on its side: two pairs per data set).

  scripts/paired-ratios.py RESULTS/jobs.csv rear:front 'min(rear-triple,front-triple):five'
  scripts/paired-ratios.py RESULTS/jobs.csv rear:front+rear-right:front-right

The figures of docs/accuracy.md's paired tables come from it. Jobs that are not done are
left out and counted on standard error; a pair whose A or B is missing is left out."""

import argparse
import csv
import math
import sys

def read_jobs(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise ValueError(f"{path}: no jobs")
    columns = list(rows[0].keys())
    for needed in ("job", "seed", "configuration", "state", "drift_rate_pct"):
        if needed not in columns:
            raise ValueError(f"{path}: no column '{needed}'")
    axes = columns[1:columns.index("seed")]
    data = {}
    skipped = 0
    for line, r in enumerate(rows, start=2):
        if r["state"] != "done":
            skipped += 1
            continue
        try:
            drift = float(r["drift_rate_pct"])
        except ValueError:
            raise ValueError(f"{path}: line {line}: drift_rate_pct '{r['drift_rate_pct']}' is not a number")
        if not drift > 0.0 or math.isinf(drift):
            raise ValueError(f"{path}: line {line}: drift_rate_pct {drift} is not a positive number")
        condition = tuple(r[a] for a in axes)
        key = (condition, r["seed"])  # the data set: the condition's axes and the seed
        data.setdefault(key, {})[r["configuration"]] = drift
    return axes, data, skipped


def configurations(spec):
    """The configurations one side of a pair names: X, or each of min(X,Y,...)."""
    if spec.startswith("min(") and spec.endswith(")"):
        return [n.strip() for n in spec[4:-1].split(",")]
    return [spec]


def side(spec, runs):
    """The drift of one side of a pair on one data set (the lowest of a min(...)), or None when
    a configuration is missing."""
    values = [runs.get(n) for n in configurations(spec)]
    return None if any(v is None for v in values) else min(values)


def split_outside(text, sep):
    """text split at each `sep` outside parentheses."""
    depth, parts, start = 0, [], 0
    for i, ch in enumerate(text):
        depth += (ch == "(") - (ch == ")")
        if ch == sep and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    return parts + [text[start:]]


def split_pair(pair):
    """A:B split at the colon outside parentheses; None unless there is exactly one."""
    halves = split_outside(pair, ":")
    if len(halves) != 2 or not all(halves):
        return None
    return halves[0], halves[1]


def summary(ratios, bound):
    if not ratios:
        return "no pairs"
    geo = math.exp(sum(math.log(x) for x in ratios) / len(ratios))
    no_worse = sum(x <= bound for x in ratios)
    return (f"{no_worse} of {len(ratios)} no worse ({100.0 * no_worse / len(ratios):.0f} %), "
            f"geo-mean {geo:.2f}, worst {max(ratios):.2f}, best {min(ratios):.2f}")


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("jobs", help="a study's jobs.csv")
    p.add_argument("pairs", nargs="+", help="A:B (B over A); A or B may be min(X,Y,...); A:B+C:D pools pairs")
    p.add_argument("--bound", type=float, default=1.05, help="the largest ratio counted as no worse")
    a = p.parse_args(argv)
    try:
        axes, data, skipped = read_jobs(a.jobs)
    except (OSError, ValueError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if skipped:
        print(f"{a.jobs}: {skipped} jobs not done, left out", file=sys.stderr)
    known = set(c for runs in data.values() for c in runs)
    for pooled in a.pairs:
        pairs = [split_pair(pair) for pair in split_outside(pooled, "+")]
        if any(halves is None for halves in pairs):
            print(f"error: pair '{pooled}' is not A:B (or A:B+C:D)", file=sys.stderr)
            return 2
        for first, second in pairs:
            for n in configurations(first) + configurations(second):
                if n not in known:
                    print(f"error: {a.jobs}: no configuration '{n}' (there are: {', '.join(sorted(known))})",
                          file=sys.stderr)
                    return 2
        by_condition = {}
        for (condition, *_), runs in sorted(data.items()):
            for first, second in pairs:
                lo, hi = side(first, runs), side(second, runs)
                if lo is not None and hi is not None:
                    by_condition.setdefault(condition, []).append(hi / lo)
        title = " with ".join(f"{second} against {first}" for first, second in pairs)
        print(f"{title}: {summary([x for v in by_condition.values() for x in v], a.bound)}")
        for condition, ratios in by_condition.items():
            label = ", ".join(f"{ax} {v}" for ax, v in zip(axes, condition))
            print(f"  {label}: {summary(ratios, a.bound)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
