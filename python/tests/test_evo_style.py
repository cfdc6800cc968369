"""An evo_ape-style check of what wheelins writes: the TUM trajectory of `wheelins run` and the
TUM truth of `wheelins evaluate --export-truth`, read as plain TUM files and compared the way
evo compares them (time stamps associated, the translation error in the plane),
give the horizontal RMSE `wheelins evaluate` reports. Computed here with numpy only, from the
two files, independently of the evaluator. Run by CTest (python_tests)."""

import json
import os
import subprocess

import numpy as np

WHEELINS = os.environ.get("WHEELINS_BINARY", "wheelins")


def cli(*args):
    p = subprocess.run([WHEELINS, *map(str, args)], capture_output=True, text=True)
    assert p.returncode == 0, f"wheelins {' '.join(map(str, args))}: {p.returncode}\n{p.stderr}"
    return p


def read_tum(path):
    """The records (t x y z qx qy qz qw) and the '# key: value' header lines of a TUM file."""
    header, rows = {}, []
    with open(path) as f:
        for line in f:
            if line.startswith("#"):
                key, _, value = line[1:].strip().partition(":")
                if value:
                    header[key.strip()] = value.split("(")[0].split()
            elif line.strip():
                rows.append([float(x) for x in line.split()])
    return np.array(rows), header


def associate(ref_t, est_t, max_diff):
    """For every reference stamp, the nearest estimate stamp within max_diff (evo's rule)."""
    j = np.clip(np.searchsorted(est_t, ref_t), 1, len(est_t) - 1)
    nearer = np.where(np.abs(est_t[j - 1] - ref_t) <= np.abs(est_t[j] - ref_t), j - 1, j)
    ok = np.abs(est_t[nearer] - ref_t) <= max_diff
    return np.nonzero(ok)[0], nearer[ok]


def test_tum_files_give_the_evaluations_horizontal_rmse(tmp_path):
    sim = tmp_path / "sim"
    cli("simulate", "--out", sim, "--duration", "50", "--static", "10", "--chips", "1", "-q")
    run = tmp_path / "run"
    cli("run", "--full-rate", "-m", sim / "manifest.yaml", "-c", "single", "-o", run, "--tum-frame", "enu", "-q")
    truth_tum = tmp_path / "truth.tum"
    p = cli("evaluate", "--truth", sim / "GINS.bin", "--traj", run / "trajectory.tum", "--export-truth", truth_tum,
            "--json", "-")
    metrics = json.loads(p.stdout)

    est, est_header = read_tum(run / "trajectory.tum")
    ref, ref_header = read_tum(truth_tum)
    # Both say they are ENU about the same origin, so `evo_ape tum truth.tum trajectory.tum` compares like with like.
    assert est_header["frame"] == ["enu"] and ref_header["frame"] == ["enu"]
    assert est_header["origin"] == ref_header["origin"]

    # The run writes every IMU epoch, on the truth's 200 Hz grid: stamps pair exactly (evo's
    # --t_max_diff 1e-6). evo's default 0.01 s also pairs the truth stamp just before the
    # trajectory's first, which the evaluation leaves out (no extrapolation): 5th digit.
    i, j = associate(ref[:, 0], est[:, 0], 1e-6)
    assert len(i) == metrics["epochs"]
    d = ref[i, 1:3] - est[j, 1:3]  # x, y: east and north, the plane of evo's --project_to_plane xy
    rmse = np.sqrt(np.mean(np.sum(d * d, axis=1)))
    assert rmse > 0.01  # a real error, not two copies of one file
    # (to 1e-6: the evaluation takes each error in its truth point's own north/east/down, which
    # turn with the earth's curvature along the track; the TUM files share one local frame)
    np.testing.assert_allclose(rmse, metrics["rms_error_m"], rtol=1e-6)
    i, j = associate(ref[:, 0], est[:, 0], 0.01)
    d = ref[i, 1:3] - est[j, 1:3]
    np.testing.assert_allclose(np.sqrt(np.mean(np.sum(d * d, axis=1))), metrics["rms_error_m"], rtol=1e-3)
