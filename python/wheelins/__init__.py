"""wheelins: dead reckoning for wheeled vehicles from wheel-mounted and body IMUs.

The Python face of the C++ library (the native part is wheelins._core, pybind11). A
simulated dataset, a run on it and its figures (this example runs as a doctest):

    >>> import tempfile, wheelins
    >>> out = tempfile.mkdtemp()
    >>> info = wheelins.simulate(out + "/sim", duration_s=40, static_s=10, chips=1, write_ideal=False)
    >>> result = wheelins.run(info["manifest"], configuration="triple")
    >>> result.metrics["rms_error_m"] < 1.0               # keyed as `wheelins evaluate --json`
    True
    >>> sorted(result.calibration["modules"]) == sorted(result.modules)   # calibration.yaml as a dict
    True
    >>> type(result.faults["events"]), sorted(result.faults["modules"]) == sorted(result.modules)  # faults.csv
    (<class 'list'>, True)
    >>> nav = wheelins.Navigator(info["manifest"], configuration="triple")
    >>> nav.modules == result.modules
    True

A Navigator is fed sample by sample: nav.push("left-C1", t, gyro, accel) in rad/s and
m/s^2, then nav.state["heading_deg"], nav.covariance("left-C1"). The reports are dicts
(.noise, .calibration, .faults) with their text kept (.noise_report, .calibration_report,
.fault_report; .noise_yaml and .calibration_yaml as the files hold them).

Every error the command line reports as "error: MESSAGE" is raised as
wheelins.InputError (a ValueError) with the same MESSAGE, its options spelled as Python
takes them (force=True). A misspelled keyword is a TypeError naming it. Ctrl-C stops a
call (KeyboardInterrupt; nothing half-written is left). See docs/python.md.
"""

import difflib as _difflib
import json as _json
import os as _os
import shutil as _shutil
import tempfile as _tempfile

import numpy as _np

from . import _core
from ._core import InputError

__all__ = ["InputError", "Navigator", "Result", "csv_columns", "evaluate", "read_truth", "run", "simulate"]


# The keyword arguments of run() and Navigator() beyond their named ones: the options of
# `wheelins run` by name, from the run settings' declarations (--no-position-constraint is
# position_constraint=False, --fixed-noise fixed_noise=True, --output-interval output_interval).
_RUN_KEYWORDS = dict(_core.run_keywords())  # keyword -> the setting's key (docs/run-config.md)
_NAMED = ("manifest", "configuration", "chips", "modules")
_RUN_SETTINGS = tuple(k for k in _RUN_KEYWORDS if k not in _NAMED + ("out", "formats", "force", "full_rate",
                                                                      "subsystems")) + ("settings",)
_NAVIGATOR_SETTINGS = tuple(k for k, key in _RUN_KEYWORDS.items()  # not the files' (a Navigator writes none)
                            if k not in _NAMED and (key == "output.interval_s" or not key.startswith("output."))
                            ) + ("calibration_warmup", "settings")
_EVALUATE_OPTIONS = ("format", "truth_layout", "segment", "max_gap", "align", "origin")


def _check_keywords(function, given, known):
    """A TypeError naming a keyword `function` does not take (and the nearest it does)."""
    for key in given:
        if key not in known:
            near = _difflib.get_close_matches(key, known, n=1)
            hint = f"; did you mean {near[0]!r}?" if near else ""
            raise TypeError(f"{function}() got an unexpected keyword argument {key!r}{hint} "
                            f"(it takes: {', '.join(known)})")


def _run_settings(filter_settings):
    """settings={"fusion.position_std_m": 0.3} (or nested: {"fusion": {...}}): any key of the
    run configuration (docs/run-config.md), as `wheelins run --set KEY=VALUE` each."""
    settings = filter_settings.pop("settings", None)
    if settings is None:
        return filter_settings
    if not isinstance(settings, dict):
        raise InputError("settings: a dict {key: value} of the run configuration's keys (docs/run-config.md)")
    flat = []
    _flatten("", settings, flat)
    return {**filter_settings, "settings": flat}


def _yaml(text):
    return None if not text else _core.yaml_dict(text)


def csv_columns():
    """The trajectory CSV's column names, in file order (t_s, north_m, ..., sa_z_std_ppm)."""
    return list(_core.csv_columns())


def _columns(table):
    return {name: _np.ascontiguousarray(table[:, k]) for k, name in enumerate(_core.csv_columns())}


def _flatten(prefix, value, out):
    if isinstance(value, dict):
        for k, v in value.items():
            _flatten(f"{prefix}.{k}" if prefix else str(k), v, out)
    else:
        out.append(f"{prefix}={_yaml_value(value)}")


def _yaml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if v is None:
        return "null"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_yaml_value(x) for x in v) + "]"
    if isinstance(v, float):
        return repr(v)
    return str(v)


def simulate(out, *, force=False, progress=False, write_ideal=True, **settings):
    """Simulates a dataset into directory `out` (what `wheelins simulate` writes).

    `settings` are the keys of the dataset's scenario.yaml (docs/simulator.md), as
    `wheelins simulate --set KEY=VALUE` takes them: seed=3, duration_s=60, chips=1,
    static_s=10, profile="datasheet", effects=["arw", "vrw"], vehicle={"track_m": 0.4}
    (nested dicts give dotted keys). Returns a summary dict with the manifest's path.
    """
    flat = []
    for key, value in settings.items():
        _flatten(key, value, flat)
    return _core.simulate(out, flat, force=force, progress=progress, write_ideal=write_ideal)


class Result:
    """A run: .trajectory (dict of numpy arrays keyed by the trajectory CSV's header names,
    in its units), .metrics (the evaluation against the manifest's truth, keyed as
    `wheelins evaluate --json`; None without a truth file), .stats, .weights (the
    reference weights of eq. (8) at every constraint epoch, as weights.csv: dict of numpy
    arrays, "t_s" and one per module; empty for a single IMU), .modules, .files (written
    when run(out=...)). The reports as dicts and as text:
    .noise (noise.yaml: the noise model identified), .noise_report (as printed by
    `wheelins run`), .noise_yaml; .calibration (calibration.yaml: the installation
    estimates; None with calibration="manifest"), .calibration_report, .calibration_yaml;
    .faults ({"events": [{"t_s", "module", "detected", "action"}, ...], "modules": {name:
    counts}}, as faults.csv), .fault_report; .weights_report."""

    def __init__(self, output):
        self._output = output
        self.trajectory = _columns(output.table)
        self.metrics = None if output.metrics_json is None else _json.loads(output.metrics_json)
        self.stats = output.stats
        self.fault_report = output.fault_report
        self.noise_report = output.noise_report
        self.calibration_report = output.calibration_report
        self.noise_yaml = output.noise_yaml
        self.noise = _yaml(output.noise_yaml)
        self.calibration_yaml = output.calibration_yaml or None
        self.calibration = _yaml(output.calibration_yaml)
        self.faults = output.faults
        self.weights_report = output.weights_report
        w = output.weights_table
        self.weights = {} if w.shape[0] == 0 else {
            name: _np.ascontiguousarray(w[:, k]) for k, name in enumerate(["t_s"] + list(output.modules))}
        self.modules = list(output.modules)
        self.files = list(output.files)
        self.origin = list(output.origin_deg)  # the trajectory's north/east/down origin

    def __repr__(self):
        n = len(self.trajectory["t_s"])
        return f"<wheelins.Result {'+'.join(self.modules)}: {n} records>"


def run(manifest, configuration=None, chips=None, *, modules=None, config=None, out=None, formats=None,
        evaluate=True, progress=False, force=None, full_rate=None, subsystems=None, **filter_settings):
    """Navigates a dataset as `wheelins run` does and returns a Result.

    configuration: single | dual-wheel | body-wheel | triple; chips: e.g. ["C1", "C4"]
    (or "C1,C4"); modules: explicit module names; config: a run configuration YAML
    (docs/run-config.md), which the other arguments override; out: a directory to write
    the trajectory files to (default: none written): a record every 0.1 s unless
    full_rate=True, and each IMU's own trajectory with subsystems=True (as `wheelins run
    --full-rate --subsystems`); the Result holds every record either way. filter_settings are the options of
    `wheelins run` by name: speed="mean", centralized=True, position_constraint=False,
    fault_handling=False, duration=60.0, output_interval=0.1, covariance_interval=0.0,
    weights="covariance" (or "equal"), fixed_noise=True, yaw_scale_factors="held" (or "auto",
    "constraint", "estimated"), calibration="manifest" (or "estimate", the default: the
    Wheel-IMUs' mounting and lever arm estimated from the data first), standstill=False,
    data_checks=False, tum_frame="enu"; every option of `wheelins run` that sets a run
    setting, named as its long option without "--" (and "no-"), "-" as "_". settings: any key
    of the run configuration (docs/run-config.md) as `--set` takes it, e.g.
    settings={"fusion.position_std_m": 0.3, "fusion.weights": [1, 2, 1]}.
    """
    _check_keywords("run", filter_settings, _RUN_SETTINGS)
    if isinstance(chips, str):
        chips = [c for c in chips.split(",") if c]
    keywords = {"manifest": manifest, "configuration": configuration or None, "chips": list(chips or []) or None,
                "modules": list(modules or []) or None, "formats": list(formats or []) or None, "force": force,
                "full_rate": full_rate, "subsystems": subsystems}
    settings = _run_settings(filter_settings)
    flat = settings.pop("settings", [])
    return Result(_core.run(config=config, out=out, evaluate=evaluate, progress=progress,
                            keywords={**keywords, **settings}, settings=flat))


_SERIES = ["t_s", "distance_m", "err_n_m", "err_e_m", "err_d_m", "err_h_m", "heading_err_deg", "sigma_h_m", "nees_h"]
_TRUTH = ["t_s", "north_m", "east_m", "down_m", "lat_deg", "lon_deg", "h_m", "vn_m_s", "ve_m_s", "vd_m_s",
          "roll_deg", "pitch_deg", "heading_deg"]


def evaluate(truth, trajectory, *, series=False, **options):
    """The metrics of a trajectory against a truth file, keyed as `wheelins evaluate --json`.

    trajectory: a file (wheelins CSV, TUM, Wheel-INS traj.txt) or a Result. options as
    `wheelins evaluate`: format, truth_layout, segment, max_gap, align, origin=[lat, lon, h].
    series=True adds "series": the per-epoch errors as `wheelins evaluate --series` writes
    them (dict of numpy arrays: t_s, distance_m, err_n_m, ..., nees_h).
    """
    _check_keywords("evaluate", options, _EVALUATE_OPTIONS)
    if isinstance(trajectory, Result):
        trajectory = trajectory._output
    text, table = _core.evaluate(truth, trajectory, series=series, **options)
    metrics = _json.loads(text)
    if series:
        metrics["series"] = {name: _np.ascontiguousarray(table[:, k]) for k, name in enumerate(_SERIES)}
    return metrics


def read_truth(truth, origin=None):
    """A truth file (GINS.bin) as a dict of numpy arrays: t_s, north_m, east_m, down_m about
    `origin` ([lat_deg, lon_deg, h_m]; default its first record; a Result's .origin is the
    frame of its trajectory), lat_deg, lon_deg, h_m, vn/ve/vd_m_s, roll/pitch/heading_deg."""
    table = _core.read_truth(truth, origin=None if origin is None else list(origin))
    return {name: _np.ascontiguousarray(table[:, k]) for k, name in enumerate(_TRUTH)}


class Navigator:
    """A run fed sample by sample: Navigator(manifest, configuration=..., chips=...,
    modules=..., **filter_settings) (the options of run()); manifest is a manifest file or
    the module specs as a dict with the manifest's keys (docs/manifest.md; no "file"
    needed). Then push(module, t, gyro,
    accel) for every IMU record in time order across the modules (module: a name or its
    index in .modules; t [s] as in the data file; gyro [rad/s], accel [m/s^2]; or the
    increments when the manifest says format: increment). The same samples through the
    same code as `wheelins run` give the same trajectory to the last digit.

    calibration="estimate" (default "manifest": the manifest's geometry as it is) estimates
    the installation geometry (docs/filter.md section 15) from the first calibration_warmup
    seconds (default 120) after the static period: their samples are kept, and navigated with
    the estimates when the warm-up ends (or at finish()), so nothing is output before then;
    later samples are navigated as they come. The estimates are a run's with that duration.

    .state: the vehicle solution now (dict keyed like the trajectory CSV; None before
    navigation starts); .covariance(module): that subsystem's 21x21 error-state
    covariance; .trajectory: the output records so far (dict of numpy arrays).
    """

    def __init__(self, manifest, configuration=None, chips=None, *, modules=None, config=None, **filter_settings):
        _check_keywords("Navigator", filter_settings, _NAVIGATOR_SETTINGS)
        if isinstance(chips, str):
            chips = [c for c in chips.split(",") if c]
        tmp = None
        if isinstance(manifest, dict):
            # Module specs without a file: the manifest's keys (docs/manifest.md) as a dict,
            # handed to the manifest reader as JSON (which is YAML); no data file is read.
            spec = dict(manifest)
            spec.setdefault("format", "wheelins-manifest-1")
            spec["modules"] = [dict(m, file=m.get("file", "(pushed samples)")) for m in spec.get("modules", [])]
            spec.pop("truth", None)
            spec.pop("odometer", None)
            tmp = _tempfile.mkdtemp(prefix="wheelins-")
            manifest = _os.path.join(tmp, "manifest (from a dict).yaml")
            with open(manifest, "w") as f:
                _json.dump(spec, f)
        try:
            settings = _run_settings(filter_settings)
            warmup = settings.pop("calibration_warmup", 120.0)
            flat = settings.pop("settings", [])
            keywords = {"manifest": manifest, "configuration": configuration or None,
                        "chips": list(chips or []) or None, "modules": list(modules or []) or None, **settings}
            self._nav = _core.Navigator(config=config, keywords=keywords, calibration_warmup=warmup, settings=flat)
        finally:
            if tmp:
                _shutil.rmtree(tmp, ignore_errors=True)

    def push(self, module, t, gyro, accel):
        """One IMU record; False once the duration limit is reached (later samples are ignored)."""
        return self._nav.push(module, float(t), gyro, accel)

    def finish(self):
        """Ends the data (closes the fault statistics); an InputError if navigation never started."""
        self._nav.finish()

    def covariance(self, module=0):
        return self._nav.covariance(module)

    @property
    def state(self):
        return self._nav.state

    @property
    def modules(self):
        return list(self._nav.modules)

    @property
    def navigating(self):
        return self._nav.navigating

    @property
    def trajectory(self):
        return _columns(self._nav.table)

    @property
    def stats(self):
        return self._nav.stats

    @property
    def fault_report(self):
        return self._nav.fault_report

    @property
    def faults(self):
        """The fault report as a dict: {"events": [...], "modules": {...}} (as Result.faults)."""
        return self._nav.faults

    @property
    def noise(self):
        """The noise model now, as noise.yaml's dict (the text: .noise_yaml)."""
        return _yaml(self._nav.noise_yaml)

    @property
    def noise_yaml(self):
        return self._nav.noise_yaml

    @property
    def calibration(self):
        """With calibration="estimate": the warm-up's estimates as calibration.yaml's dict
        (None before the warm-up ends, and with the manifest's geometry); the text:
        .calibration_yaml."""
        return _yaml(self._nav.calibration)

    @property
    def calibration_yaml(self):
        """The same as calibration.yaml's text (None as .calibration)."""
        return self._nav.calibration

    @property
    def calibration_report(self):
        """The same as a readable table (None as .calibration)."""
        return self._nav.calibration_report
