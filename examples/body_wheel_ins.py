# %% [markdown]
# # Body/Wheel-INS on a simulated dataset
#
# A notebook-style script (cells marked `# %%`): simulate a robot with two Wheel-IMUs and
# a Body-IMU, navigate it with Body/Wheel-INS (the Body-IMU and the left Wheel-IMU), and
# plot the trajectory against the truth and the horizontal error with its 3-sigma bound.
#
#     PYTHONPATH=build/python /usr/bin/python3 examples/body_wheel_ins.py [OUT_DIR] [--duration S]
#
# writes OUT_DIR/sim/ (the dataset) and OUT_DIR/body_wheel_ins.png (default OUT_DIR:
# out/example). The test suite runs it (headless, matplotlib's Agg backend).

# %%
import argparse
import os
import sys

import matplotlib

if not os.environ.get("DISPLAY"):
    matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import wheelins

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("out", nargs="?", default="out/example")
parser.add_argument("--duration", type=float, default=240.0, help="seconds of data (default 240)")
args = parser.parse_args()
os.makedirs(args.out, exist_ok=True)

# %% Simulate: one chip per module, the field error profile, a 30 s static start.
sim_dir = os.path.join(args.out, "sim")
info = wheelins.simulate(sim_dir, force=True, write_ideal=False, duration_s=args.duration, chips=1, seed=7)
print(f"simulated {info['duration_s']:.0f} s, {info['distance_m']:.0f} m -> {info['manifest']}")

# %% Navigate: Body/Wheel-INS, evaluated against the dataset's truth as `wheelins run` does.
result = wheelins.run(info["manifest"], configuration="body-wheel")
m = result.metrics
print(f"{result}: heading RMSE {m['heading_rmse_deg']:.3f} deg, max error {m['max_error_m']:.2f} m, "
      f"final error {m['final_error_m']:.2f} m, drift rate "
      + ("n/a (shorter than one segment)" if m["drift_rate_pct"] is None else f"{m['drift_rate_pct']:.2f} %"))

# %% The truth in the trajectory's frame, and the per-epoch errors.
truth = wheelins.read_truth(os.path.join(sim_dir, "GINS.bin"), origin=result.origin)
errors = wheelins.evaluate(os.path.join(sim_dir, "GINS.bin"), result, series=True, origin=result.origin)["series"]
traj = result.trajectory

# %% Plot.
fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 5))
ax1.plot(truth["east_m"], truth["north_m"], "k-", lw=2, label="truth")
ax1.plot(traj["east_m"], traj["north_m"], "C1-", lw=1, label="Body/Wheel-INS")
ax1.set_xlabel("east [m]")
ax1.set_ylabel("north [m]")
ax1.set_aspect("equal", adjustable="datalim")
ax1.legend()
ax1.set_title("trajectory")
t0 = errors["t_s"][0]
ax2.plot(errors["t_s"] - t0, errors["err_h_m"], "C0-", label="horizontal error")
ax2.plot(errors["t_s"] - t0, 3 * errors["sigma_h_m"], "C3--", label="3 sigma")
ax2.set_xlabel("time since navigation start [s]")
ax2.set_ylabel("[m]")
ax2.legend()
ax2.set_title("error")
fig.tight_layout()
png = os.path.join(args.out, "body_wheel_ins.png")
fig.savefig(png, dpi=100)
print(f"wrote {png}")
if not np.all(np.isfinite(traj["north_m"])):
    sys.exit("non-finite positions in the trajectory")
