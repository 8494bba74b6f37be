"""``flagwrap analyze`` end to end: a tiny real run, a synthetic wrapped run file, bad input."""

import json
import subprocess
import sys

import numpy as np
import pytest

from flagwrap.analysis import STATES
from flagwrap.cli.main import main
from flagwrap.io.runfile import config_of, read_run

from conftest import tiny_toml

TINY = tiny_toml(ccw=0.3, cw=0.3)


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("analyze")
    cfgp = d / "tiny.toml"
    cfgp.write_text(TINY)
    out = d / "tiny.nc"
    assert main(["run", str(cfgp), "-o", str(out), "--quiet"]) == 0
    return out


def test_analyze_writes_attributes_and_is_idempotent(tiny_run, capsys):
    before = read_run(tiny_run)
    assert main(["analyze", str(tiny_run)]) == 0
    text = capsys.readouterr().out
    assert "final state" in text and "stable" in text
    ds = read_run(tiny_run)
    assert ds.attrs["analysis_state"] == "stable" and ds.attrs["analysis_buckled"] == 0
    assert ds.attrs["analysis_switch_turns"] == pytest.approx(0.3)
    assert json.loads(ds.attrs["analysis_params"])["threshold"] == 0.15
    np.testing.assert_allclose(ds["free_end_height"].values,
                               (ds.position.values[:, -1, 2] - ds.position.values[:, 0, 2]) / 0.4)
    # run data untouched
    np.testing.assert_array_equal(ds.position.values, before.position.values)
    assert ds.attrs["config_toml"] == before.attrs["config_toml"]
    # rerun with other criteria replaces the results, leaves no temp files
    assert main(["analyze", str(tiny_run), "--threshold", "0.2", "--json"]) == 0
    res = json.loads(capsys.readouterr().out.strip())
    assert res["state"] in STATES and res["waiting_time_turns"] is None
    assert json.loads(read_run(tiny_run).attrs["analysis_params"])["threshold"] == 0.2
    assert sorted(p.name for p in tiny_run.parent.iterdir()) == ["tiny.nc", "tiny.toml"]


def test_synthetic_wrapped_run_file(tiny_run, tmp_path, capsys):
    """Replace the tiny run's trajectory by one that rises at t/T = 0.4 and winds once."""
    ds = read_run(tiny_run)
    cfg = config_of(ds)
    R = cfg.filament.helix_radius
    Rc = cfg.body.resolved_radius(R)
    x = ds.position.values.copy()
    n = x.shape[1]
    th = np.linspace(0, 2 * np.pi, n - 2)
    coil = np.stack([1.1 * Rc * np.cos(th), 1.1 * Rc * np.sin(th), 0.05 + 0.01 * th], axis=1)
    wrapped = np.vstack([[0, 0, 0], [0.5 * Rc, 0, 0], coil])
    t = ds.turns.values
    x[t >= 0.4 - 1e-9] = wrapped
    ds["position"] = (("time", "bead", "xyz"), x, ds["position"].attrs)
    p = tmp_path / "wrapped.nc"
    ds.to_netcdf(p, engine="h5netcdf")
    assert main(["analyze", str(p), "--json", "--hold-turns", "0.1", "--smooth-turns", "0.05",
                 "--final-turns", "0.1"]) == 0
    res = json.loads(capsys.readouterr().out.strip())
    assert res["state"] == "wrapping"
    assert res["waiting_time_turns"] == pytest.approx(0.1, abs=0.051)
    assert res["winding_turns"] == pytest.approx(1.0, abs=0.05)
    assert read_run(p).attrs["analysis_state"] == "wrapping"


def test_no_write_leaves_file_alone(tiny_run, tmp_path, capsys):
    p = tmp_path / "copy.nc"
    p.write_bytes(tiny_run.read_bytes())
    data = p.read_bytes()
    for flag in ("--no-write", "--no-store"):
        assert main(["analyze", str(p), flag]) == 0
        assert p.read_bytes() == data
        out = capsys.readouterr().out
        assert "summary stored" not in out and f"not stored (--no-store): {p} unchanged" in out


def test_analyze_says_it_rewrites_the_run_file(tiny_run, tmp_path, capsys):
    # the default stores the summary in the file: the output says so, on one line, last
    p = tmp_path / "copy.nc"
    p.write_bytes(tiny_run.read_bytes())
    data = p.read_bytes()
    assert main(["analyze", str(p)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[-1].strip().startswith(f"summary stored in {p} (attributes analysis_*")
    assert sum("summary stored" in line for line in out) == 1
    assert p.read_bytes() != data and "analysis_state" in read_run(p).attrs
    # --json: stdout stays one JSON object, the line goes to stderr
    assert main(["analyze", str(p), "--json"]) == 0
    cap = capsys.readouterr()
    assert json.loads(cap.out)["state"] == "stable"
    assert cap.err.startswith(f"summary stored in {p}")


def test_bad_input_exit_2(tmp_path):
    bad = tmp_path / "bad.nc"
    bad.write_bytes(b"not a run file")
    r = subprocess.run([sys.executable, "-m", "flagwrap.cli.main", "analyze", str(bad)],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "Traceback" not in r.stderr and "error:" in r.stderr
    assert main(["analyze", str(tmp_path / "missing.nc")]) == 2
    assert main(["analyze", str(bad), "--threshold", "-1"]) == 2


def test_ccw_only_run_is_reported(tiny_run, tmp_path, capsys):
    ds = read_run(tiny_run)
    ds["omega"] = ("time", np.abs(ds.omega.values), ds["omega"].attrs)
    p = tmp_path / "ccw.nc"
    ds.to_netcdf(p, engine="h5netcdf")
    assert main(["analyze", str(p)]) == 2
    assert "never turns CW" in capsys.readouterr().err


def test_run_files_with_the_old_integrator_name_still_load(tiny_run):
    # run files written before the ROS2 stepper was renamed say integrator = "rosenbrock"
    ds = read_run(tiny_run)
    text = ds.attrs["config_toml"]
    assert 'integrator = "ros34pw2"' in text
    ds.attrs["config_toml"] = text.replace('integrator = "ros34pw2"', 'integrator = "rosenbrock"')
    assert config_of(ds).numerics.integrator == "ros2"
