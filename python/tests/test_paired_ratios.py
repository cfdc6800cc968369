"""scripts/paired-ratios.py (docs/accuracy.md's paired tables): the ratios B / A on the same
data, per condition and over all, with min(...) as the best of several configurations; bad
input is refused by name. Run by CTest (python_tests)."""

import os
import subprocess
import sys

SOURCE = os.environ.get("WHEELINS_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
SCRIPT = os.path.join(SOURCE, "scripts", "paired-ratios.py")
HEADER = "job,profile,terrain,seed,configuration,state,drift_rate_pct,heading_rmse_deg\n"


def jobs(tmp_path, rows):
    path = tmp_path / "jobs.csv"
    path.write_text(HEADER + "".join(f"{i},{r}\n" for i, r in enumerate(rows)))
    return path


def ratios(path, *pairs):
    return subprocess.run([sys.executable, SCRIPT, str(path), *pairs], capture_output=True, text=True)


def test_ratios_per_condition_and_the_best_of_several(tmp_path):
    path = jobs(tmp_path, [
        "field,0,1,a,done,0.2,1", "field,0,1,b,done,0.1,1", "field,0,1,c,done,0.4,1",
        "field,0,2,a,done,0.2,1", "field,0,2,b,done,0.8,1", "field,0,2,c,done,0.3,1",
        "datasheet,0,1,a,done,0.1,1", "datasheet,0,1,b,done,0.104,1", "datasheet,0,1,c,done,0.2,1",
        "datasheet,0,2,a,done,0.1,1", "datasheet,0,2,b,failed,,", "datasheet,0,2,c,done,0.2,1",
    ])
    p = ratios(path, "a:b", "min(a,c):b")
    assert p.returncode == 0, p.stderr
    lines = p.stdout.splitlines()
    # b / a: 0.5, 4.0 (field), 1.04 (datasheet; seed 2's b failed and is left out)
    assert lines[0] == "b against a: 2 of 3 no worse (67 %), geo-mean 1.28, worst 4.00, best 0.50"
    assert lines[1] == "  profile datasheet, terrain 0: 1 of 1 no worse (100 %), geo-mean 1.04, worst 1.04, best 1.04"
    assert lines[2] == "  profile field, terrain 0: 1 of 2 no worse (50 %), geo-mean 1.41, worst 4.00, best 0.50"
    # against the better of a and c: field seed 2 is 0.8 / 0.2
    assert lines[3].startswith("b against min(a,c): 2 of 3 no worse")
    assert "1 jobs not done" in p.stderr


def test_pairs_pooled(tmp_path):
    path = jobs(tmp_path, [
        "field,0,1,a,done,0.2,1", "field,0,1,b,done,0.1,1", "field,0,1,c,done,0.4,1", "field,0,1,d,done,0.1,1",
        "field,0,2,a,done,0.2,1", "field,0,2,b,done,0.8,1", "field,0,2,c,done,0.3,1",
    ])
    p = ratios(path, "a:b+c:d")
    assert p.returncode == 0, p.stderr
    lines = p.stdout.splitlines()
    # b / a: 0.5 and 4.0; d / c: 0.25 (seed 2 has no d: that pair is left out)
    assert lines[0] == "b against a with d against c: 2 of 3 no worse (67 %), geo-mean 0.79, worst 4.00, best 0.25"
    assert lines[1] == "  profile field, terrain 0: 2 of 3 no worse (67 %), geo-mean 0.79, worst 4.00, best 0.25"
    p = ratios(path, "a:b+c")
    assert p.returncode == 2 and "'a:b+c' is not A:B" in p.stderr


def test_bad_input_is_named(tmp_path):
    path = jobs(tmp_path, ["field,0,1,a,done,0.2,1", "field,0,1,b,done,nan,1"])
    p = ratios(path, "a:b")
    assert p.returncode == 2 and "line 3" in p.stderr and "drift_rate_pct" in p.stderr
    path = jobs(tmp_path, ["field,0,1,a,done,0.2,1", "field,0,1,b,done,0.3,1"])
    p = ratios(path, "a:x")
    assert p.returncode == 2 and "no configuration 'x'" in p.stderr
    p = ratios(path, "a-b")
    assert p.returncode == 2 and "'a-b' is not A:B" in p.stderr
    p = ratios(tmp_path / "none.csv", "a:b")
    assert p.returncode == 2 and "none.csv" in p.stderr
