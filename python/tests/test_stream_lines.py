"""scripts/stream-lines.py piped into `wheelins live` (docs/live.md): a simulated dataset
replayed as a live stream gives the trajectory `wheelins run` writes from its files, to the
byte; with --realtime the lines come at the data's pace. Run by CTest (python_tests)."""

import os
import subprocess
import sys
import time

WHEELINS = os.environ.get("WHEELINS_BINARY", "wheelins")
SOURCE = os.environ.get("WHEELINS_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
SCRIPT = os.path.join(SOURCE, "scripts", "stream-lines.py")
MODULES = "left-C1,right-C1,body-C1"


def run(args, **kw):
    p = subprocess.run(args, capture_output=True, text=True, **kw)
    assert p.returncode == 0, f"{' '.join(map(str, args))}: {p.returncode}\n{p.stderr}"
    return p


def test_a_replayed_dataset_gives_the_file_runs_trajectory(tmp_path):
    data = tmp_path / "data"
    run([WHEELINS, "simulate", "--duration", "50", "--chips", "1", "--no-ideal", "-q", "--out", data])
    manifest = data / "manifest.yaml"
    run([WHEELINS, "run", "-m", manifest, "--modules", MODULES, "--calibration", "manifest",
         "--no-data-checks", "--no-evaluate", "-q", "-o", tmp_path / "files"])
    lines = run([sys.executable, SCRIPT, manifest, MODULES]).stdout
    assert lines.count("\n") == 3 * 50 * 200
    live = run([WHEELINS, "live", "-m", manifest, "--modules", MODULES, "--calibration", "manifest",
                "-o", tmp_path / "live"], input=lines)
    assert (tmp_path / "live" / "trajectory.csv").read_bytes() == (tmp_path / "files" / "trajectory.csv").read_bytes()
    states = live.stdout.splitlines()
    assert 195 <= len(states) <= 202 and all(s.startswith('{"t_s":') for s in states)


def test_realtime_paces_the_lines(tmp_path):
    data = tmp_path / "data"
    run([WHEELINS, "simulate", "--duration", "2", "--static", "1", "--chips", "1", "--no-ideal", "-q",
         "--out", data])
    t0 = time.monotonic()
    out = run([sys.executable, SCRIPT, data / "manifest.yaml", "left-C1", "--realtime", "--speed", "2"]).stdout
    took = time.monotonic() - t0
    assert out.count("\n") == 400
    assert 0.9 <= took < 5.0  # 2 s of data at twice real time: about 1 s


def test_refuses_a_module_not_in_the_manifest(tmp_path):
    data = tmp_path / "data"
    run([WHEELINS, "simulate", "--duration", "2", "--static", "1", "--chips", "1", "--no-ideal", "-q",
         "--out", data])
    p = subprocess.run([sys.executable, SCRIPT, data / "manifest.yaml", "nobody"], capture_output=True, text=True)
    assert p.returncode != 0 and "module 'nobody' is not in" in p.stderr
