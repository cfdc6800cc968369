"""The Python module against the command line: the same runs, the same figures, the
streaming navigator to the last digit, the same error messages. Run by CTest
(python_tests) with PYTHONPATH=build/python and WHEELINS_BINARY set."""

import csv
import json
import os
import re
import subprocess
import sys

import numpy as np
import pytest

import wheelins

WHEELINS = os.environ.get("WHEELINS_BINARY", "wheelins")
SOURCE = os.environ.get("WHEELINS_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
# The CSV's columns written at full precision (shortest round trip); the others have 9 digits.
FULL = ["t_s", "north_m", "east_m", "down_m", "lat_deg", "lon_deg", "h_m", "vn_m_s", "ve_m_s", "vd_m_s",
        "roll_deg", "pitch_deg", "heading_deg"]


def cli(*args, check=True):
    p = subprocess.run([WHEELINS, *map(str, args)], capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError(f"wheelins {' '.join(map(str, args))}: {p.returncode}\n{p.stderr}")
    return p


def read_csv(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return {name: np.array([float(r[k]) for r in rows[1:]]) for k, name in enumerate(rows[0])}


def same_as_csv(traj, csv_cols):
    """Every column of an in-memory trajectory equals the CSV: exactly where the CSV has
    full precision, at its 9 significant digits elsewhere."""
    assert list(traj) == list(csv_cols)
    for name, values in csv_cols.items():
        mine = traj[name]
        assert mine.shape == values.shape, name
        if name in FULL:
            np.testing.assert_array_equal(mine, values, err_msg=name)
        else:
            np.testing.assert_array_equal(np.array([float(f"{v:.9g}") for v in mine]), values, err_msg=name)


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("sim")
    info = wheelins.simulate(out / "sim", duration_s=40, static_s=10, chips=1, seed=5, write_ideal=False)
    assert os.path.exists(info["manifest"])
    return info


@pytest.fixture(scope="module")
def cli_triple(dataset, tmp_path_factory):
    out = tmp_path_factory.mktemp("cli")
    p = cli("run", "--full-rate", "-m", dataset["manifest"], "-c", "triple", "-o", out, "-q")
    return out, p.stdout


def test_simulate_writes_what_the_cli_writes(dataset, tmp_path):
    cli("simulate", "--out", tmp_path / "c", "--duration", 40, "--static", 10, "--chips", 1, "--seed", 5,
        "--no-ideal", "-q")
    sim = os.path.dirname(dataset["manifest"])
    for rel in ["left-wheel-imu/tri_C1_imu.bin", "body-imu/tri_C1_imu.bin", "GINS.bin", "odo.bin"]:
        with open(os.path.join(sim, rel), "rb") as a, open(tmp_path / "c" / rel, "rb") as b:
            assert a.read() == b.read(), rel


def test_run_gives_the_cli_trajectory_and_figures(dataset, cli_triple):
    out, stdout = cli_triple
    r = wheelins.run(dataset["manifest"], configuration="triple")
    assert r.modules == ["left-C1", "right-C1", "body-C1"]
    same_as_csv(r.trajectory, read_csv(out / "trajectory.csv"))
    # The figures `wheelins run` prints come from the same evaluation.
    m = r.metrics
    printed = {
        "distance_m": (r"distance\s+([\d.]+) m", 1),
        "heading_rmse_deg": (r"heading RMSE\s+([\d.]+) deg", 3),
        "max_error_m": (r"max / final error\s+([\d.]+) /", 2),
        "final_error_m": (r"max / final error\s+[\d.]+ / ([\d.]+) m", 2),
        "mean_nees_h": (r"mean NEES ([\d.]+)", 2),
    }
    for key, (pattern, digits) in printed.items():
        found = re.search(pattern, stdout)
        assert found, (key, stdout)
        assert f"{m[key]:.{digits}f}" == found.group(1), key
    # evaluate() of the written trajectory is `wheelins evaluate --json` of it.
    truth = os.path.join(os.path.dirname(dataset["manifest"]), "GINS.bin")
    mine = wheelins.evaluate(truth, out / "trajectory.csv")
    theirs = json.loads(cli("evaluate", "--truth", truth, "--traj", out / "trajectory.csv", "--json", "-").stdout)
    assert mine == theirs
    # ... and of the run in memory, the same figures to the CSV's rounding.
    memory = wheelins.evaluate(truth, r)
    for key in ["distance_m", "max_error_m", "final_error_m", "rms_error_m", "heading_rmse_deg"]:
        assert memory[key] == pytest.approx(theirs[key], rel=1e-9, abs=1e-12), key
    series = wheelins.evaluate(truth, r, series=True)["series"]
    assert len(series["t_s"]) == memory["epochs"]


def test_run_options_and_files(dataset, tmp_path):
    r = wheelins.run(dataset["manifest"], "body-wheel", out=tmp_path / "bw", formats=["csv"], centralized=True,
                     position_constraint=False, duration=15.0, output_interval=0.1, full_rate=True)
    cli("run", "--full-rate", "-m", dataset["manifest"], "-c", "body-wheel", "-o", tmp_path / "cli", "--formats", "csv",
        "--centralized", "--no-position-constraint", "--duration", 15, "--output-interval", 0.1, "-q")
    same_as_csv(r.trajectory, read_csv(tmp_path / "cli" / "trajectory.csv"))
    same_as_csv(r.trajectory, read_csv(tmp_path / "bw" / "trajectory.csv"))
    assert str(tmp_path / "bw" / "trajectory.csv") in r.files
    with pytest.raises(TypeError):
        wheelins.run(dataset["manifest"], no_such_setting=1)


def test_run_weights_and_fixed_noise_as_the_cli(dataset, tmp_path):
    r = wheelins.run(dataset["manifest"], "triple", out=tmp_path / "py", formats=["csv"], weights="covariance",
                     fixed_noise=True, duration=40.0, output_interval=0.1)
    cli("run", "--full-rate", "-m", dataset["manifest"], "-c", "triple", "-o", tmp_path / "cli", "--formats", "csv",
        "--weights", "covariance", "--fixed-noise", "--duration", 40, "--output-interval", 0.1, "-q")
    same_as_csv(r.trajectory, read_csv(tmp_path / "cli" / "trajectory.csv"))
    theirs = read_csv(tmp_path / "cli" / "weights.csv")
    assert list(r.weights) == ["t_s"] + r.modules
    assert len(r.weights["t_s"]) == len(theirs["t"]) > 20
    for m in r.modules:
        assert r.weights[m] == pytest.approx(theirs[m], abs=1e-6), m
    total = sum(r.weights[m] for m in r.modules)
    assert total == pytest.approx(np.ones_like(total), abs=1e-9)
    assert "inverse variance" in r.weights_report
    assert "(the given figures, held fixed)" in r.noise_report
    single = wheelins.run(dataset["manifest"], "single", duration=5.0)
    assert single.weights == {}
    with pytest.raises(ValueError, match="expected equal, covariance or standalone"):
        wheelins.run(dataset["manifest"], "triple", weights="inverse", duration=5.0)


def test_keywords_are_the_options_of_wheelins_run(dataset, tmp_path):
    """Every option of `wheelins run` that sets a run setting is a keyword, named from its
    declaration (issue 35): standstill=False is --no-standstill, data_checks=False
    --no-data-checks, tum_frame="enu" --tum-frame enu; a wrong value names the keyword."""
    r = wheelins.run(dataset["manifest"], "dual-wheel", out=tmp_path / "py", duration=15.0, standstill=False,
                     data_checks=False, tum_frame="enu", fault_handling=False, full_rate=True)
    cli("run", "-m", dataset["manifest"], "-c", "dual-wheel", "-o", tmp_path / "cli", "--duration", 15,
        "--no-standstill", "--no-data-checks", "--tum-frame", "enu", "--no-fault-handling", "--full-rate", "-q")
    same_as_csv(r.trajectory, read_csv(tmp_path / "cli" / "trajectory.csv"))
    assert (tmp_path / "py" / "trajectory.tum").read_text() == (tmp_path / "cli" / "trajectory.tum").read_text()
    nav = wheelins.Navigator(dataset["manifest"], configuration="dual-wheel", standstill=False, weights="covariance",
                             duration=np.float32(15.0), output_interval=np.int64(0))  # numpy's numbers too
    assert nav.modules == r.modules
    with pytest.raises(wheelins.InputError, match=r"^duration: duration_s: must be > 0 s"):
        wheelins.run(dataset["manifest"], duration=0.0)
    with pytest.raises(wheelins.InputError, match="standstill: expected True or False"):
        wheelins.run(dataset["manifest"], standstill="no")
    with pytest.raises(TypeError, match="'full_rate'"):
        wheelins.Navigator(dataset["manifest"], full_rate=True)  # an output's keyword: not the Navigator's


def test_settings_set_any_key_as_the_clis_set(dataset, tmp_path):
    settings = {"fusion.position_std_m": 0.5, "fusion.weights": [1, 2, 1], "standstill.enabled": False}
    r = wheelins.run(dataset["manifest"], "triple", out=tmp_path / "py", formats=["csv"], duration=20.0,
                     settings=settings)
    cli("run", "--full-rate", "-m", dataset["manifest"], "-c", "triple", "-o", tmp_path / "cli", "--formats", "csv",
        "--duration", 20, "--set", "fusion.position_std_m=0.5", "--set", "fusion.weights=[1, 2, 1]",
        "--set", "standstill.enabled=false", "-q")
    same_as_csv(r.trajectory, read_csv(tmp_path / "cli" / "trajectory.csv"))
    plain = wheelins.run(dataset["manifest"], "triple", duration=20.0)
    assert not np.array_equal(plain.trajectory["north_m"], r.trajectory["north_m"])
    nav = wheelins.Navigator(dataset["manifest"], configuration="triple", settings={"filter.velocity_update_hz": 4})
    assert nav is not None
    with pytest.raises(ValueError, match="fusion.position_std: unknown key"):
        wheelins.run(dataset["manifest"], "triple", duration=5.0, settings={"fusion.position_std": 0.5})
    with pytest.raises(ValueError, match=r"must be in \[0.001, 100\] m"):
        wheelins.run(dataset["manifest"], "triple", duration=5.0, settings={"fusion.position_std_m": 500})
    with pytest.raises(ValueError, match="a dict"):
        wheelins.run(dataset["manifest"], "triple", duration=5.0, settings=["fusion.position_std_m=1"])


def load_rows(dataset, module_file):
    return np.fromfile(os.path.join(os.path.dirname(dataset["manifest"]), module_file), dtype="<f8").reshape(-1, 7)


WHEEL_L, WHEEL_R, BODY = "left-wheel-imu/tri_C1_imu.bin", "right-wheel-imu/tri_C1_imu.bin", "body-imu/tri_C1_imu.bin"


@pytest.mark.parametrize("configuration,files,settings,flags", [
    ("triple", [WHEEL_L, WHEEL_R, BODY], {}, []),
    ("body-wheel", [WHEEL_L, BODY], {"centralized": True, "speed": "own", "covariance_interval": 0.0},
     ["--centralized", "--speed", "own", "--covariance-interval", "0"]),
])
def test_streaming_navigator_reproduces_the_cli_to_the_last_digit(dataset, tmp_path, configuration, files, settings,
                                                                   flags):
    # The streaming navigator takes the manifest's geometry as it is: so does this run.
    cli("run", "--full-rate", "-m", dataset["manifest"], "-c", configuration, "-o", tmp_path, "-q", "--calibration", "manifest", *flags)
    nav = wheelins.Navigator(dataset["manifest"], configuration=configuration, **settings)
    assert len(nav.modules) == len(files)
    # The simulated manifest has no time offsets: merge by the file times, ties in module order.
    rows = [load_rows(dataset, f) for f in files]
    order = sorted((r[k, 0], i, k) for i, r in enumerate(rows) for k in range(len(r)))
    assert nav.state is None
    half = len(order) // 2
    for n, (_, i, k) in enumerate(order):
        row = rows[i][k]
        nav.push(i if n % 2 else nav.modules[i], row[0], row[1:4], row[4:7])
        if n == half:
            state = nav.state
            assert state is not None and set(state) == set(wheelins.csv_columns())
            assert state["north_std_m"] > 0
            if settings.get("centralized"):
                with pytest.raises(wheelins.InputError, match="joint covariance"):
                    nav.covariance(0)
            else:
                P = nav.covariance(nav.modules[0])
                assert P.shape == (21, 21)
                np.testing.assert_allclose(P, P.T, rtol=0, atol=1e-12 * np.abs(P).max())
                assert np.all(np.linalg.eigvalsh(0.5 * (P + P.T)) > -1e-12 * np.abs(P).max())
    nav.finish()
    same_as_csv(nav.trajectory, read_csv(tmp_path / "trajectory.csv"))


def test_streaming_navigator_applies_the_runs_input_checks(dataset, tmp_path):
    """A gyro sample beyond the sensor range: the run leaves it out (fault handling on) and
    so does the navigator, to the last digit."""
    import shutil
    sim = os.path.dirname(dataset["manifest"])
    copy = tmp_path / "spike"
    shutil.copytree(sim, copy)
    rows = load_rows(dataset, WHEEL_L).copy()
    rows[5000, 2] = 1e6  # rad/s
    rows.astype("<f8").tofile(copy / WHEEL_L)
    p = cli("run", "--full-rate", "-m", copy / "manifest.yaml", "-c", "body-wheel", "-o", tmp_path / "out", "-q",
            "--calibration", "manifest")
    assert "beyond the sensor range" in p.stderr or "beyond the sensor range" in p.stdout
    nav = wheelins.Navigator(copy / "manifest.yaml", configuration="body-wheel")
    data = [rows, load_rows(dataset, BODY)]
    for _, i, k in sorted((r[k, 0], i, k) for i, r in enumerate(data) for k in range(len(r))):
        nav.push(i, data[i][k][0], data[i][k][1:4], data[i][k][4:7])
    nav.finish()
    same_as_csv(nav.trajectory, read_csv(tmp_path / "out" / "trajectory.csv"))


def test_streaming_navigator_estimates_the_geometry_over_a_warmup(dataset, tmp_path):
    """calibration="estimate": the samples of the first calibration_warmup seconds after the
    static period are kept and calibrated, then navigated with the estimates. A warm-up
    longer than the data is the run's calibration from all of it (the run's trajectory to the
    last digit); a shorter one gives the run's estimates from that many seconds."""
    manifest = dataset["manifest"]
    cli("run", "--full-rate", "-m", manifest, "-c", "body-wheel", "-o", tmp_path / "all", "-q", "--calibration", "estimate")
    rows = [load_rows(dataset, WHEEL_L), load_rows(dataset, BODY)]
    order = sorted((r[k, 0], i, k) for i, r in enumerate(rows) for k in range(len(r)))

    nav = wheelins.Navigator(manifest, configuration="body-wheel", calibration="estimate", calibration_warmup=1000)
    for _, i, k in order:
        assert nav.push(i, rows[i][k][0], rows[i][k][1:4], rows[i][k][4:7])
    assert not nav.navigating and nav.state is None and nav.calibration is None
    assert len(nav.trajectory["t_s"]) == 0 and nav.calibration_report is None
    assert isinstance(nav.stats, dict) and isinstance(nav.fault_report, str)
    with pytest.raises(wheelins.InputError, match="warm-up"):
        nav.covariance(0)
    nav.finish()
    same_as_csv(nav.trajectory, read_csv(tmp_path / "all" / "trajectory.csv"))
    assert nav.calibration_yaml == (tmp_path / "all" / "calibration.yaml").read_text()
    assert set(nav.calibration["modules"]) == {"left-C1", "body-C1"}

    static_end = read_csv(tmp_path / "all" / "trajectory.csv")["t_s"][0]  # navigation starts there
    nav = wheelins.Navigator(manifest, configuration="body-wheel", calibration="estimate", calibration_warmup=15)
    started = None
    for _, i, k in order:
        nav.push(i, rows[i][k][0], rows[i][k][1:4], rows[i][k][4:7])
        if started is None and nav.navigating:
            started = rows[i][k][0]
            # The kept samples are navigated at once: the records from the start are there.
            t = nav.trajectory["t_s"]
            assert len(t) > 0 and t[0] == static_end and t[-1] > static_end + 14.9
    assert started is not None and static_end + 14.99 < started < static_end + 15.02
    nav.finish()
    short = wheelins.run(manifest, configuration="body-wheel", calibration="estimate", duration=15,
                         out=tmp_path / "short")
    assert nav.calibration_report == short.calibration_report
    assert "turns" in nav.calibration_report
    assert nav.trajectory["t_s"][-1] > static_end + 29

    with pytest.raises(wheelins.InputError, match="calibration_warmup"):
        wheelins.Navigator(manifest, configuration="single", calibration="estimate", calibration_warmup=0)
    with pytest.raises(wheelins.InputError, match="calibration"):
        wheelins.Navigator(manifest, configuration="single", calibration="guess")


def test_navigator_from_module_specs(dataset, tmp_path):
    """The manifest's content as a dict (no files named) navigates like the manifest file."""
    yaml = pytest.importorskip("yaml")  # python3-yaml, installed by scripts/setup.sh
    # Floats kept as their text: a manifest number of more than 17 digits converts to SI in
    # long double precision (io/manifest.cpp), which a Python float cannot carry.
    class Exact(yaml.SafeLoader):
        pass

    Exact.add_constructor("tag:yaml.org,2002:float", lambda loader, node: loader.construct_scalar(node))
    with open(dataset["manifest"]) as f:
        spec = yaml.load(f, Loader=Exact)
    for m in spec["modules"]:
        del m["file"]
    nav = wheelins.Navigator(spec, configuration="triple")
    files = [WHEEL_L, WHEEL_R, BODY]
    rows = [load_rows(dataset, f) for f in files]
    for _, i, k in sorted((r[k, 0], i, k) for i, r in enumerate(rows) for k in range(len(r))):
        nav.push(i, rows[i][k][0], rows[i][k][1:4], rows[i][k][4:7])
    nav.finish()
    cli("run", "--full-rate", "-m", dataset["manifest"], "-c", "triple", "-o", tmp_path, "-q", "--calibration", "manifest")
    same_as_csv(nav.trajectory, read_csv(tmp_path / "trajectory.csv"))
    spec["modules"][0]["wheel_radius_m"] = -1
    with pytest.raises(wheelins.InputError, match=r"modules\[0\].wheel_radius_m"):
        wheelins.Navigator(spec)


def test_errors_are_the_cli_messages(dataset, tmp_path):
    missing = tmp_path / "nothere.yaml"
    p = cli("run", "-m", missing, "-q", check=False)
    assert p.returncode == 2
    with pytest.raises(wheelins.InputError) as e:
        wheelins.run(missing)
    assert p.stderr.strip() == f"error: {e.value}"
    assert isinstance(e.value, ValueError)
    p = cli("run", "-m", dataset["manifest"], "-c", "quadruple", "-q", check=False)
    with pytest.raises(wheelins.InputError) as e:
        wheelins.run(dataset["manifest"], configuration="quadruple")
    assert str(e.value) == "configuration: unknown configuration 'quadruple'"  # the keyword, as Python spells it
    assert p.stderr.strip().endswith(f"error: --{e.value}")

    nav = wheelins.Navigator(dataset["manifest"], configuration="body-wheel")
    with pytest.raises(wheelins.InputError, match="module 'right-C1' is not navigated"):
        nav.push("right-C1", 1.0, [0, 0, 0], [0, 0, 0])
    nav.push(0, 100000.005, [0, 0, 0], [0, 0, -9.8])
    with pytest.raises(wheelins.InputError, match=r"module '.*', sample 1 \(0-based\): time 100000.005 repeats"):
        nav.push(0, 100000.005, [0, 0, 0], [0, 0, -9.8])
    with pytest.raises(wheelins.InputError, match=r"column 5 \(accel_y\): value is NaN"):
        nav.push(0, 100000.01, [0, 0, 0], [0, float("nan"), -9.8])
    with pytest.raises(wheelins.InputError, match="before the last sample pushed"):
        nav.push(1, 99999.0, [0, 0, 0], [0, 0, -9.8])
    with pytest.raises(wheelins.InputError, match="nothing to navigate"):
        nav.finish()


def test_example_script_runs_headless(tmp_path):
    script = os.path.join(SOURCE, "examples", "body_wheel_ins.py")
    env = dict(os.environ, MPLBACKEND="Agg")
    env.pop("DISPLAY", None)
    p = subprocess.run([sys.executable, script, str(tmp_path), "--duration", "60"], capture_output=True, text=True,
                       env=env)
    assert p.returncode == 0, p.stderr
    assert "wrote" in p.stdout
    png = tmp_path / "body_wheel_ins.png"
    assert png.stat().st_size > 10000
    with open(png, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"


def test_module_docstring_runs_as_a_doctest():
    import doctest
    failed, tried = doctest.testmod(wheelins, verbose=False, report=True)
    assert tried > 5 and failed == 0


def test_reports_are_dicts_with_their_text(dataset, tmp_path):
    r = wheelins.run(dataset["manifest"], configuration="triple", out=tmp_path / "run")
    import yaml as pyyaml  # python3-yaml (scripts/setup.sh): the files' own reading
    assert r.noise == pyyaml.safe_load((tmp_path / "run" / "noise.yaml").read_text())
    assert r.noise_yaml == (tmp_path / "run" / "noise.yaml").read_text()
    assert r.calibration == pyyaml.safe_load((tmp_path / "run" / "calibration.yaml").read_text())
    assert r.calibration_yaml == (tmp_path / "run" / "calibration.yaml").read_text()
    assert "installation calibration" in r.calibration_report and isinstance(r.noise_report, str)
    rows = [line for line in (tmp_path / "run" / "faults.csv").read_text().splitlines()
            if line and not line.startswith("#")][1:]
    assert len(r.faults["events"]) == len(rows)
    assert set(r.faults["modules"]) == set(r.modules)
    assert all(set(c) >= {"gaps", "isolations", "seconds_unused"} for c in r.faults["modules"].values())
    manifest_only = wheelins.run(dataset["manifest"], configuration="single", calibration="manifest")
    assert manifest_only.calibration is None and manifest_only.calibration_yaml is None
    nav = wheelins.Navigator(dataset["manifest"], configuration="single")
    assert set(nav.faults) == {"events", "modules"} and isinstance(nav.noise, dict)


def test_messages_are_phrased_for_python(dataset, tmp_path):
    """A misspelled keyword is a TypeError naming it (not the binding's signature), and the
    messages name force=True, not the command line's --force."""
    with pytest.raises(TypeError) as e:
        wheelins.run(dataset["manifest"], configuration="triple", centralised=True)
    assert "'centralised'" in str(e.value) and "did you mean 'centralized'" in str(e.value)
    assert "Invoked with" not in str(e.value)
    with pytest.raises(TypeError, match="'warmup'"):
        wheelins.Navigator(dataset["manifest"], warmup=3)
    with pytest.raises(TypeError, match="'segments'.*did you mean 'segment'"):
        wheelins.evaluate(dataset["manifest"], dataset["manifest"], segments=10)
    (tmp_path / "sim").mkdir()
    (tmp_path / "sim" / "keep.txt").write_text("mine")
    with pytest.raises(wheelins.InputError) as e:
        wheelins.simulate(tmp_path / "sim", duration_s=20, chips=1)
    assert "force=True" in str(e.value) and "--force" not in str(e.value)
    with pytest.raises(wheelins.InputError) as e:
        wheelins.simulate(tmp_path / "sim2", duration_s="long")
    assert "--set" not in str(e.value) and "duration_s" in str(e.value)


def test_ctrl_c_stops_a_long_call_at_once(tmp_path):
    """Ctrl-C during a call into the library (here an hour's simulation, a minute or two of
    work): KeyboardInterrupt within a fraction of a second, not at the end, and no data file
    left behind."""
    import _thread
    import threading
    import time
    timer = threading.Timer(0.3, _thread.interrupt_main)
    t0 = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        wheelins.simulate(tmp_path / "long", duration_s=3600, chips=1, write_ideal=False)
    timer.join()
    assert time.monotonic() - t0 < 2.0
    assert [p for p in (tmp_path / "long").rglob("*") if p.is_file()] == []


def test_ctrl_c_during_runs_leaves_only_complete_results(dataset, tmp_path):
    """Runs back to back, Ctrl-C among them: KeyboardInterrupt, and every output directory
    there is complete (an interrupted run removes its unfinished output)."""
    import _thread
    import threading
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        for k in range(200):
            wheelins.run(dataset["manifest"], configuration="triple", calibration="manifest",
                         out=tmp_path / f"run{k}")
    timer.join()
    # (on a busy machine the first run may be the one interrupted: then there is none)
    for d in tmp_path.iterdir():
        assert {p.name for p in d.iterdir()} >= {"trajectory.csv", "noise.yaml", "faults.csv"}, d


def test_force_replaces_only_what_wheelins_wrote(dataset, tmp_path):
    """run(force=True) over an earlier run's directory replaces that run's files and keeps the
    user's own (issue 33, item 4); a file of the user's under a name the run writes is refused."""
    out = tmp_path / "single"
    wheelins.run(dataset["manifest"], "single", out=out, formats=["csv"], duration=5.0)
    (out / "notes.txt").write_text("mine")
    (out / "later-run").mkdir()
    (out / "later-run" / "trajectory.csv").write_text("my other results")
    before = (out / "trajectory.csv").read_text()
    wheelins.run(dataset["manifest"], "single", out=out, formats=["csv"], duration=6.0, force=True)
    assert (out / "notes.txt").read_text() == "mine"
    assert (out / "later-run" / "trajectory.csv").read_text() == "my other results"
    assert (out / "trajectory.csv").read_text() != before
    with pytest.raises(wheelins.InputError, match="already holds results.*force=True replaces the files"):
        wheelins.run(dataset["manifest"], "single", out=out, formats=["csv"], duration=5.0)
