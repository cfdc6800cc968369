"""scripts/draw-bound.py (docs/accuracy.md, "What one draw per chip allows"): the share of
paired draws in which adding the Body-IMU is no worse, against the closed form where there is
one, and bad input refused by name. Run by CTest (python_tests)."""

import math
import os
import subprocess
import sys

SOURCE = os.environ.get("WHEELINS_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
SCRIPT = os.path.join(SOURCE, "scripts", "draw-bound.py")


def bound(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


def rows(stdout):
    """{W: (Body/Wheel share %, geo, Triple share %, geo)} from the table."""
    out = {}
    for line in stdout.splitlines()[2:]:
        f = line.replace("%", " ").replace(",", " ").split()
        # W, share, no, worse, geo, g, share, no, worse, geo, g
        out[float(f[0])] = (float(f[1]), float(f[5]), float(f[6]), float(f[10]))
    return out


def test_equal_weights_against_the_closed_form():
    # Body/Wheel with the body as good as the wheel and equal weights: the ratio |e1 + b| /
    # (2 |e1|) is at most c when b / e1 lies in [-(2c + 1), 2c - 1]; for independent normal
    # draws of equal variance that has probability (atan(2c - 1) + atan(2c + 1)) / pi.
    c = 1.05
    expected = 100.0 * (math.atan(2 * c - 1) + math.atan(2 * c + 1)) / math.pi  # 66.6 %
    p = bound("--body-var", "1", "--weights", "1", "--draws", "100000")
    assert p.returncode == 0, p.stderr
    share, geo, _, _ = rows(p.stdout)[1.0]
    assert abs(share - expected) < 0.6, (share, expected)
    assert geo < 1.0  # better on average


def test_no_weight_is_never_worse_and_less_weight_is_safer_but_gains_less():
    p = bound("--body-var", "2", "--weights", "1,0.1,0", "--draws", "20000")
    assert p.returncode == 0, p.stderr
    r = rows(p.stdout)
    assert r[0.0] == (100.0, 1.0, 100.0, 1.0)
    assert r[1.0][0] < r[0.1][0] < 100.0 and r[1.0][2] < r[0.1][2] < 100.0
    assert r[0.1][3] > r[1.0][3]  # the Triple's gain on average shrinks with the weight


def test_bad_input_is_refused_by_name():
    for args, name in [(["--weights", "1,x"], "--weights"), (["--weights", "-1"], "--weights"),
                       (["--body-var", "0"], "--body-var"), (["--draws", "10"], "--draws")]:
        p = bound(*args)
        assert p.returncode == 2, (args, p.stdout)
        assert name in p.stderr, (args, p.stderr)
