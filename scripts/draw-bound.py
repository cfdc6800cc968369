#!/usr/bin/env python3
"""What paired comparisons can show when each IMU's heading error is one draw of its chip
(docs/accuracy.md, "What one draw per chip allows"). Each module's heading error is taken as
one independent normal draw per data set (as a yaw-rate scale factor's, which multiplies the
heading turned), a Wheel-IMU's of variance 1, the Body-IMU's of variance --body-var; the fused
heading error is the weighted mean (the Body-IMU at weight W against 1 for each wheel, eq. 8)
and the drift is taken as proportional to its magnitude. For each W it prints how often
Body/Wheel is no worse than its wheel alone and Triple no worse than Dual (ratio <= --bound),
and the geometric mean of the ratios: the best any fusion with those weights can do in a
paired study when one draw per chip dominates the error.

  scripts/draw-bound.py --body-var 1 --weights 1,0.5,0.25,0.1,0.03
"""

import argparse
import math
import random


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--body-var", type=float, default=1.0,
                    help="the Body-IMU's heading-error variance over a Wheel-IMU's (default 1)")
    ap.add_argument("--weights", default="1,0.5,0.25,0.1,0.03",
                    help="the Body-IMU's weights W to try, comma-separated (each wheel 1)")
    ap.add_argument("--draws", type=int, default=200000, help="draws of the chips (default 200000)")
    ap.add_argument("--bound", type=float, default=1.05, help="a ratio up to this is no worse (default 1.05)")
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    try:
        weights = [float(w) for w in a.weights.split(",")]
    except ValueError:
        ap.error(f"--weights '{a.weights}': expected numbers separated by commas")
    if not all(w >= 0.0 and math.isfinite(w) for w in weights):
        ap.error(f"--weights '{a.weights}': every weight must be finite and >= 0")
    if not (a.body_var > 0.0 and math.isfinite(a.body_var)):
        ap.error(f"--body-var {a.body_var}: must be finite and > 0")
    if a.draws < 1000:
        ap.error(f"--draws {a.draws}: at least 1000")
    rng = random.Random(a.seed)
    sb = math.sqrt(a.body_var)
    draws = [(rng.gauss(0, 1), rng.gauss(0, 1), rng.gauss(0, sb)) for _ in range(a.draws)]
    print(f"body variance {a.body_var:g} x a wheel's, {a.draws} draws, no worse: ratio <= {a.bound:g}")
    print(f"{'W':>6}  {'Body/Wheel vs wheel':>26}  {'Triple vs Dual':>26}")
    for w in weights:
        n_bw = n_tr = 0
        log_bw = log_tr = 0.0
        used = 0
        for e1, e2, b in draws:
            single, dual = abs(e1), abs(e1 + e2) / 2.0
            if single == 0.0 or dual == 0.0:
                continue
            bw = abs(e1 + w * b) / (1.0 + w)
            tr = abs(e1 + e2 + w * b) / (2.0 + w)
            r_bw, r_tr = bw / single, tr / dual
            used += 1
            n_bw += r_bw <= a.bound
            n_tr += r_tr <= a.bound
            log_bw += math.log(max(r_bw, 1e-300))
            log_tr += math.log(max(r_tr, 1e-300))
        print(f"{w:6g}  {100.0 * n_bw / used:5.1f} % no worse, geo {math.exp(log_bw / used):4.2f}"
              f"  {100.0 * n_tr / used:5.1f} % no worse, geo {math.exp(log_tr / used):4.2f}")


if __name__ == "__main__":
    main()
