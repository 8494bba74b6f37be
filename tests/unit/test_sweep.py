"""Sweeps (issue 5): spec -> cases, case keys, atomic rows, resume after SIGKILL, failed cases,
LocalCluster vs in-process identical tables, boundary bisection.

Oracle for the physics-free parts: a fake case function (``fake_sweep_runner.run``, written to
a temporary folder and put on the path of this process and of every worker/subprocess) whose
verdict is ``buckled <=> M > 0.2 (R/L)^-3`` and which raises for ``M > 1e5``.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from flagwrap.errors import UserInputError
from flagwrap.sweep.spec import Case, resolve_geometry, spec_from_dict

FAKE = textwrap.dedent('''
    import os, time
    def run(cfg, path, stop_after):
        log = os.environ.get("FAKE_SWEEP_LOG")
        if log:
            with open(log, "a") as fh:
                fh.write(f"{cfg.machin:.9g} {cfg.filament.helix_radius:.9g}\\n")
        time.sleep(float(os.environ.get("FAKE_SWEEP_SLEEP", "0")))
        if cfg.machin > 1e5:
            raise RuntimeError(f"boom: M = {cfg.machin:.6g} is too large")
        rl = cfg.filament.helix_radius / cfg.filament.length
        buckled = cfg.machin > 0.2 * rl ** -3
        return {"buckled": buckled, "state": ("wrapping" if rl > 0.05 else "folding") if buckled else "stable",
                "waiting_time_turns": 1.5 if buckled else float("nan"), "run_status": "completed",
                "message": ""}
''')


@pytest.fixture
def fake(tmp_path, monkeypatch):
    d = tmp_path / "fakemod"
    d.mkdir()
    (d / "fake_sweep_runner.py").write_text(FAKE)
    monkeypatch.syspath_prepend(str(d))
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(d), os.environ.get("PYTHONPATH", "")]))
    # registered by the user's environment (this process and every subprocess), never by
    # the sweep file, which only names it
    monkeypatch.setenv("FLAGWRAP_SWEEP_RUNNERS", "fake=fake_sweep_runner:run")
    return "fake"


def _spec(runner, **extra):
    d = {"name": "t", "runner": runner, "base": {"filament": {"n_beads": 21}},
         "grid": {"psi_deg": [40.0, 70.0], "turns": [2.0, 3.0], "omega_ratio_scaling": [1.0, 5.0]}}
    d.update(extra)
    return spec_from_dict(d)


def test_geometry_from_two_of_three():
    psi, n, rl = resolve_geometry(70.0, 2.0, None)
    assert rl == pytest.approx(math.sin(math.radians(70)) / (4 * math.pi))
    assert resolve_geometry(70.0, None, rl)[1] == pytest.approx(2.0)
    assert resolve_geometry(None, 2.0, rl)[0] == pytest.approx(70.0)
    with pytest.raises(UserInputError, match="inconsistent"):
        resolve_geometry(60.0, 2.0, rl)
    with pytest.raises(UserInputError, match="two of"):
        resolve_geometry(70.0, None, None)


def test_case_config_matches_geometry():
    c = spec_from_dict({"grid": {"psi_deg": 70.0, "turns": 2.0, "machin": 283.0}}).cases[0]
    cfg = c.config()
    assert cfg.filament.pitch_angle_deg == pytest.approx(70.0)
    assert cfg.filament.turns == pytest.approx(2.0)
    assert cfg.filament.cross_section_radius / cfg.filament.length == pytest.approx(1.5 / 400)
    assert cfg.machin == pytest.approx(283.0)
    assert cfg.body.radius_ratio == 0.6 and cfg.numerics.hydrodynamics


def test_grid_expansion_and_speeds():
    s = spec_from_dict({"grid": {"psi_deg": [40.0, 70.0], "turns": [2.0, 3.0],
                                 "omega_ratio_scaling": [1.0, 2.0, 4.0], "hi": [True, False]}})
    assert len(s.cases) == 2 * 2 * 3 * 2
    for c in s.cases:
        assert c.machin == pytest.approx(c.omega_ratio_scaling * 0.06 * c.r_over_l ** -3)
    with pytest.raises(UserInputError, match="exactly one of machin"):
        spec_from_dict({"grid": {"psi_deg": 70.0, "turns": 2.0}})
    with pytest.raises(UserInputError, match="unknown key"):
        spec_from_dict({"grid": {"psi_deg": 70.0, "turns": 2.0, "machin": 1.0, "colour": 1}})


def test_key_is_hash_of_sorted_json():
    c = spec_from_dict({"grid": {"psi_deg": 70.0, "turns": 2.0, "machin": 283.0}}).cases[0]
    text = json.dumps(c.hash_payload(), sort_keys=True, separators=(",", ":"))
    assert c.key == hashlib.sha256(text.encode()).hexdigest()[:16]
    assert c.hash_payload()["version"]
    assert c.with_machin(284.0).key != c.key
    import dataclasses

    assert dataclasses.replace(c, hi=False).key != c.key
    assert dataclasses.replace(c, base={"filament": {"n_beads": 31}}).key != c.key
    assert Case(**{f.name: getattr(c, f.name) for f in dataclasses.fields(c)}).key == c.key


def test_failed_case_is_recorded_and_sweep_goes_on(tmp_path, fake):
    from flagwrap.sweep.runner import run_sweep
    from flagwrap.sweep.store import SweepStore

    spec = _spec(fake, cases=[{"psi_deg": 70.0, "turns": 2.0, "machin": 2e5}])
    rep = run_sweep(spec, tmp_path / "s", scheduler="synchronous")
    assert (rep.total, rep.finished, rep.failed) == (9, 8, 1)
    df = SweepStore(tmp_path / "s").table()
    bad = df[df.status == "failed"]
    assert len(bad) == 1 and "RuntimeError: boom: M = 200000" in bad.error.iloc[0]
    assert set(df[df.status == "ok"].state) <= {"stable", "wrapping", "folding"}
    assert rep.table_path.is_file()
    # re-run: nothing recomputed; --retry-failed recomputes only the failed one
    rep2 = run_sweep(spec, tmp_path / "s", scheduler="synchronous")
    assert (rep2.skipped, rep2.finished, rep2.failed) == (9, 0, 0)
    assert len(rep2.failed_before) == 1 and "boom" in rep2.failed_before[0][1]  # still failed
    rep3 = run_sweep(spec, tmp_path / "s", scheduler="synchronous", retry_failed=True)
    assert (rep3.skipped, rep3.failed) == (8, 1)


def test_sigkill_and_resume(tmp_path, fake):
    spec = tmp_path / "kill.toml"
    spec.write_text(textwrap.dedent(f'''
        name = "kill"
        runner = "{fake}"
        [base]
        filament = {{ n_beads = 21 }}
        [grid]
        psi_deg = [40.0, 55.0, 70.0]
        turns = [2.0, 3.0]
        omega_ratio_scaling = [1.0, 5.0]
    '''))
    out = tmp_path / "out"
    rows = out / "kill" / "rows"
    cmd = [sys.executable, "-m", "flagwrap.cli.main", "sweep", str(spec), "--scheduler",
           "synchronous", "--out", str(out), "--no-progress"]
    env = dict(os.environ, FAKE_SWEEP_SLEEP="0.4", FAKE_SWEEP_LOG=str(tmp_path / "log1"))
    p = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    t0 = time.time()
    while len(list(rows.glob("*.json"))) < 4 and time.time() - t0 < 60:
        assert p.poll() is None, p.stderr.read().decode()
        time.sleep(0.05)
    p.send_signal(signal.SIGKILL)
    p.wait()
    done = {json.loads(f.read_text())["key"]: json.loads(f.read_text()) for f in rows.glob("*.json")}
    assert 4 <= len(done) < 12
    env["FAKE_SWEEP_LOG"] = str(tmp_path / "log2")
    env["FAKE_SWEEP_SLEEP"] = "0"
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    rerun = set((tmp_path / "log2").read_text().split("\n")) - {""}
    finished_before = {f"{d['machin']:.9g} {d['r_over_l'] * 0.4:.9g}" for d in done.values()}
    assert not rerun & finished_before  # nothing finished was recomputed
    assert len(rerun) == 12 - len(done)
    files = sorted(rows.glob("*"))
    assert [f.suffix for f in files] == [".json"] * 12  # no temporary leftovers
    from flagwrap.sweep.store import SweepStore

    df = SweepStore(out / "kill").table()
    assert len(df) == 12 and df.key.is_unique and (df.status == "ok").all()
    for k, d in done.items():  # rows written before the kill are untouched
        assert df.set_index("key").loc[k, "finished_at"] == d["finished_at"]


def test_localcluster_and_synchronous_give_identical_tables(tmp_path, fake):
    pytest.importorskip("dask.distributed")
    import pandas.testing as pdt

    from flagwrap.sweep.runner import run_sweep
    from flagwrap.sweep.store import SweepStore

    spec = _spec(fake, cases=[{"psi_deg": 70.0, "turns": 2.0, "machin": 2e5}])
    run_sweep(spec, tmp_path / "sync", scheduler="synchronous")
    rep = run_sweep(spec, tmp_path / "local", scheduler="local", n_workers=2)
    assert (rep.finished, rep.failed) == (8, 1)
    a = SweepStore(tmp_path / "sync").table(volatile=False)
    b = SweepStore(tmp_path / "local").table(volatile=False)
    pdt.assert_frame_equal(a, b)
    assert len(a) == 9


def test_boundary_mode_bisection(tmp_path, fake):
    from flagwrap.sweep.boundary import brackets_from_rows
    from flagwrap.sweep.runner import run_sweep
    from flagwrap.sweep.store import SweepStore

    spec = spec_from_dict({"name": "b", "mode": "boundary", "runner": fake,
                           "base": {"filament": {"n_beads": 21}},
                           "grid": {"psi_deg": [40.0, 70.0], "turns": [2.0, 3.0]},
                           "boundary": {"rtol": 0.05, "guess_ratio": 1.0, "max_runs": 20}})
    rep = run_sweep(spec, tmp_path / "b", scheduler="synchronous")
    assert (rep.total, rep.finished, rep.failed) == (4, 4, 0)
    store = SweepStore(tmp_path / "b")
    res = store.boundaries()
    for b in res:
        truth = 0.2 * b["r_over_l"] ** -3
        assert b["converged"]
        assert b["bracket"][0] < truth <= b["bracket"][1]
        assert b["n_runs"] <= 4 + math.ceil(math.log2(math.log(2) / math.log(1.05))) + 1
    # every test run is also a row, and the rows give the same brackets
    br = {round(b["r_over_l"], 9): b for b in brackets_from_rows(store.iter_rows())}
    for b in res:
        assert br[round(b["r_over_l"], 9)]["machin_c"] == pytest.approx(b["machin_c"])
    n_rows = len(list(store.iter_rows()))
    rep2 = run_sweep(spec, tmp_path / "b", scheduler="synchronous")
    assert rep2.skipped == 4 and len(list(store.iter_rows())) == n_rows


def test_cli_dry_run(tmp_path, capsys):
    from flagwrap.cli.main import main

    assert main(["sweep", "examples/sweeps/fig5-quick.toml", "--dry-run", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "36 cases" in out and out.count("todo") == 36


@pytest.mark.parametrize("name", ["fig5.toml", "fig5-quick.toml"])
def test_shipped_sweeps_parse(name):
    from flagwrap.sweep.spec import load_spec

    s = load_spec(Path("examples/sweeps") / name)
    psi = [c.psi_deg for c in s.cases]
    n = [c.turns for c in s.cases]
    rl3 = [c.r_over_l ** 3 for c in s.cases]
    assert min(psi) == pytest.approx(33.0) and max(psi) == pytest.approx(70.0)
    assert min(n) == 1.5 and max(n) == 3.5
    assert max(rl3) / min(rl3) >= 10
    assert all(c.hi for c in s.cases)
    for c in s.cases:
        c.config()  # every geometry is a valid config (no self-overlap)


def test_real_tiny_case_writes_run_file_and_row(tmp_path):
    """The default case function end to end (13 beads, 1 CCW + 1.5 CW turns, tol 1e-3)."""
    from flagwrap.io.runfile import read_run
    from flagwrap.sweep.runner import run_case
    from flagwrap.sweep.store import SweepStore

    s = spec_from_dict({"run": {"ccw_turns": 1.0, "cw_turns": 1.5},
                        "base": {"filament": {"n_beads": 13}, "numerics": {"tol": 1e-3}},
                        "grid": {"psi_deg": 70.0, "turns": 1.5, "omega_ratio_scaling": 2.0}})
    row = run_case(s.cases[0], tmp_path)
    assert row["status"] == "ok" and row["buckled"] is False and row["state"] == "stable"
    assert row["run_status"] == "completed"
    ds = read_run(row["run_file"])
    assert ds.attrs.get("status") == "completed"
    assert SweepStore(tmp_path).read_row(row["key"])["key"] == row["key"]


def test_verdict_needs_completed_run_for_stable():
    from flagwrap.sweep.runner import verdict

    assert verdict({"buckled": False, "state": "stable", "run_status": "completed"}) == ("ok", None)
    assert verdict({"buckled": True, "state": "folding", "run_status": "failed"}) == ("ok", None)
    st, err = verdict({"buckled": False, "state": "stable", "run_status": "failed", "message": "dt_min"})
    assert st == "failed" and "dt_min" in err
    assert verdict({"buckled": None, "state": "failed"})[0] == "failed"


def _sweep_cli(tmp_path, fake, body, name="c"):
    from flagwrap.cli.main import main

    spec = tmp_path / f"{name}.toml"
    spec.write_text(f'name = "{name}"\nrunner = "{fake}"\n' + textwrap.dedent(body))
    return main(["sweep", str(spec), "--scheduler", "synchronous", "--out", str(tmp_path / "out"),
                 "--no-progress"])


def test_rerun_with_failed_cases_still_exits_1(tmp_path, fake, capsys):
    body = """
        [base]
        filament = { n_beads = 21 }
        [[cases]]
        psi_deg = 70.0
        turns = 2.0
        machin = 2e5
    """
    assert _sweep_cli(tmp_path, fake, body) == 1
    assert _sweep_cli(tmp_path, fake, body) == 1  # nothing rerun, the case is still failed
    assert "failed in an earlier run" in capsys.readouterr().out


def test_table_holds_the_current_spec_only(tmp_path, fake):
    """Rows of an earlier version of the spec (other tolerance) stay on disk, reusable, but
    the table and the diagram's rows are the current spec's."""
    from flagwrap.sweep.store import SweepStore

    def body(tol):
        return f"""
        [base]
        filament = {{ n_beads = 21 }}
        numerics = {{ tol = {tol} }}
        [grid]
        psi_deg = [70.0]
        turns = [2.0]
        machin = [100.0, 500.0]
        """
    assert _sweep_cli(tmp_path, fake, body(1e-4)) == 0
    assert _sweep_cli(tmp_path, fake, body(1e-3)) == 0
    store = SweepStore(tmp_path / "out" / "c")
    assert len(list(store.iter_rows(everything=True))) == 4
    assert len(store.table()) == 2 and len(list(store.iter_rows())) == 2
    assert _sweep_cli(tmp_path, fake, body(1e-4)) == 0  # back: reused, not rerun
    assert len(store.table()) == 2


def test_boundary_test_runs_rerun_when_the_stop_rule_changes(tmp_path, fake, monkeypatch):
    """The search's run cache is keyed by the config *and* the case function and stop_after:
    a changed [run] stop_after must run the test runs again (not reuse the old verdicts)."""
    log = tmp_path / "calls"
    monkeypatch.setenv("FAKE_SWEEP_LOG", str(log))

    def body(stop_after):
        return f"""
        mode = "boundary"
        [base]
        filament = {{ n_beads = 21 }}
        [run]
        stop_after = {stop_after}
        [grid]
        psi_deg = [70.0]
        turns = [2.0]
        [boundary]
        rtol = 0.3
        guess_ratio = 1.0
        """
    assert _sweep_cli(tmp_path, fake, body("2.0"), name="b") == 0
    n1 = len(log.read_text().splitlines())
    assert _sweep_cli(tmp_path, fake, body("false"), name="b") == 0
    assert len(log.read_text().splitlines()) == 2 * n1  # every test run again
    from flagwrap.sweep.store import SweepStore

    store = SweepStore(tmp_path / "out" / "b")
    assert len(store.boundaries()) == 1  # the current geometry result only
    assert len(list(store.iter_rows())) == n1


@pytest.mark.parametrize("change,needle", [
    ({"run": {"stop_after": "x"}}, "run.stop_after must be"),
    ({"run": {"stop_after": -3}}, "run.stop_after must be"),
    ({"run": {"stop_after": True}}, "run.stop_after must be"),
    ({"run": [1]}, r"\[run\] must be a table"),
    ({"base": {"filament": 31}}, r"\[base\] filament must be a table"),
    ({"base": {"motor": {"machn": 5}}}, r"\[base\] motor is set by each case"),
    ({"base": {"numerics": {"hydrodynamics": False}}}, "numerics.hydrodynamics is set by each case; use hi"),
    ({"base": {"filament": {"pitch": 0.1}}}, "filament.pitch is set by each case"),
    ({"base": {"body": {"radius": 0.05}}}, "body.radius is set by each case; use r_over_rcell"),
    ({"mode": "boundary", "boundary": {"max_runs": 0}}, "boundary.max_runs must be"),
    ({"mode": "boundary", "boundary": {"rtol": "x"}}, "boundary.rtol must be"),
    ({"mode": "boundary", "boundary": {"factor": 0.5}}, "boundary.factor must be"),
    ({"mode": "boundary", "grid": {"psi_deg": [70.0], "turns": [2.0], "machin": [5.0]}},
     "boundary mode searches M itself; remove machin"),
])
def test_bad_sweep_values_are_named_before_any_work(change, needle):
    d = {"name": "t", "base": {"filament": {"n_beads": 21}},
         "grid": {"psi_deg": [70.0], "turns": [2.0], "machin": [100.0]}}
    d.update(change)
    with pytest.raises(UserInputError, match=needle):
        spec_from_dict(d)


def test_sweep_cli_rejects_a_bad_scheduler_and_a_binary_file(tmp_path, capsys):
    from flagwrap.cli.main import main

    spec = tmp_path / "s.toml"
    spec.write_text('[grid]\npsi_deg = [70.0]\nturns = [2.0]\nmachin = [100.0]\n')
    assert main(["sweep", str(spec), "--scheduler", "sync", "--dry-run"]) == 2
    assert "--scheduler must be" in capsys.readouterr().err
    binary = tmp_path / "b.toml"
    binary.write_bytes(b"\xff\xfe\x00bad")
    assert main(["sweep", str(binary), "--dry-run"]) == 2
    assert "not a UTF-8 text file" in capsys.readouterr().err


def test_an_interrupted_sweep_of_a_changed_spec_shows_its_own_rows(tmp_path, fake, monkeypatch):
    # the manifest is written when the sweep starts: killed after its first case, the new
    # spec's finished row is shown and the old spec's rows are not
    from flagwrap.sweep import runner as R
    from flagwrap.sweep.runner import run_sweep
    from flagwrap.sweep.store import SweepStore

    def spec(tol):
        return _spec(fake, grid={"psi_deg": [70.0], "turns": [2.0], "machin": [100.0, 200.0, 300.0]},
                     base={"filament": {"n_beads": 21}, "numerics": {"tol": tol}})

    run_sweep(spec(1e-4), tmp_path / "s", scheduler="synchronous")
    real, calls = R.run_case, []

    def dies_on_second(case, root):
        if calls:
            raise KeyboardInterrupt
        calls.append(case)
        return real(case, root)

    monkeypatch.setattr(R, "run_case", dies_on_second)
    with pytest.raises(KeyboardInterrupt):
        run_sweep(spec(1e-5), tmp_path / "s", scheduler="synchronous")
    store = SweepStore(tmp_path / "s")
    shown = list(store.iter_rows())
    assert len(list(store.iter_rows(everything=True))) == 4
    assert [r["key"] for r in shown] == [calls[0].key]


def test_shipped_sweeps_load_by_name_from_any_folder(tmp_path, monkeypatch):
    # the sweep files are package data (flagwrap/data/sweeps; examples/sweeps links to them),
    # so a wheel install without the repository runs `flagwrap sweep fig5-quick`
    from flagwrap.errors import UserInputError
    from flagwrap.sweep.spec import builtin_specs, load_spec

    monkeypatch.chdir(tmp_path)
    assert {"fig5", "fig5-quick", "fig5-boundary", "gravity-fig4a", "gravity-fig5"} <= set(builtin_specs())
    assert load_spec("fig5-quick").name == "fig5-quick"
    assert load_spec("gravity-fig4a.toml").mode == "boundary"
    with pytest.raises(UserInputError, match="built-in sweeps: fig5"):
        load_spec("fig5-nope")
    with pytest.raises(UserInputError, match="not found"):
        load_spec("some/dir/fig5-quick")


def test_a_sweep_file_cannot_name_code_to_import(tmp_path, monkeypatch, capsys):
    # issue 33: `runner = "module:function"` in a shared sweep file imported and ran it; now a
    # file names a registered runner only, and nothing it names is imported
    from flagwrap.cli.main import main
    from flagwrap.sweep.case import RUNNERS, register_runner, runner_target

    d = tmp_path / "evil"
    d.mkdir()
    (d / "evil_mod.py").write_text(f"open({str(tmp_path / 'ran')!r}, 'w').write('x')\n"
                                   "def run(cfg, path):\n    return {{}}\n")
    monkeypatch.syspath_prepend(str(d))
    monkeypatch.delenv("FLAGWRAP_SWEEP_RUNNERS", raising=False)
    spec = tmp_path / "s.toml"
    for runner in ("evil_mod:run", "os:system", "nope"):
        spec.write_text(f'name = "s"\nrunner = "{runner}"\n[grid]\npsi_deg = [40.0]\nturns = [2.0]\n'
                        "omega_ratio_scaling = [1.0]\n")
        assert main(["sweep", str(spec), "--scheduler", "synchronous", "--dry-run",
                     "--out", str(tmp_path / "out")]) == 2
        err = capsys.readouterr().err
        assert f"runner {runner!r} is not a registered case function (registered: default" in err
    assert not (tmp_path / "ran").exists() and not (tmp_path / "out").exists()
    # registered from Python (or the environment) by the user, a file may name it
    monkeypatch.setitem(RUNNERS, "mine", "evil_mod:run")
    assert runner_target("mine") == "evil_mod:run" and runner_target(None) == RUNNERS["default"]
    with pytest.raises(ValueError, match="module:function"):
        register_runner("x", "no colon")


@pytest.mark.parametrize("name", ["..", ".", "a/b", "a\\\\b", "x\\u0000y", "-x", ".hidden", ""])
def test_a_sweep_name_is_one_folder_under_out(tmp_path, name):
    from flagwrap.errors import UserInputError

    with pytest.raises(UserInputError, match="sweep: name must be letters, digits"):
        _spec(None, name=name)


@pytest.mark.parametrize("damage, why", [
    (lambda t: t[: len(t) // 2], "not readable JSON"),
    (lambda t: t.replace('"status": "ok"', '"status": "maybe"'), "its checksum does not match"),
    (lambda t: json.dumps({k: v for k, v in json.loads(t).items() if k not in ("key", "_sha256")}),
     "no key"),
    (lambda t: json.dumps({**{k: v for k, v in json.loads(t).items() if k != "_sha256"},
                           "buckled": "maybe"}), "buckled = 'maybe' is not a bool"),
])
def test_a_damaged_row_is_named_left_out_and_computed_again(tmp_path, fake, capsys, damage, why):
    # issue 33: `sweep --dry-run` and `figure fig5` crashed on a damaged or key-less row
    from flagwrap.sweep.runner import run_sweep
    from flagwrap.sweep.store import SweepStore

    spec = _spec(fake, grid={"psi_deg": [40.0], "turns": [2.0], "omega_ratio_scaling": [1.0, 5.0]})
    run_sweep(spec, tmp_path / "s", scheduler="synchronous")
    store = SweepStore(tmp_path / "s")
    rows = sorted(store.rows.glob("*.json"))
    assert len(rows) == 2 and len(list(store.iter_rows())) == 2
    rows[0].write_text(damage(rows[0].read_text()))
    capsys.readouterr()
    assert len(list(store.iter_rows())) == 1  # left out, not a crash
    err = capsys.readouterr().err
    assert f"{rows[0]} is damaged ({why}" in err, err
    rep = run_sweep(spec, tmp_path / "s", scheduler="synchronous")  # computed again
    assert (rep.skipped, rep.failed) == (1, 0)
    capsys.readouterr()
    assert len(list(store.iter_rows())) == 2 and "is damaged" not in capsys.readouterr().err


def _write_tiny_run_file(path):
    import numpy as np
    import xarray as xr

    from flagwrap.io.runfile import write_dataset_atomic

    write_dataset_atomic(xr.Dataset({"x": ("t", np.arange(5.0))}), path)
    return str(path)


def test_a_run_file_is_written_inside_a_dask_worker_process(tmp_path):
    # every case of `flagwrap sweep fig5` on a LocalCluster failed: xarray, seeing the
    # distributed scheduler, locked the in-memory run file with a distributed Lock named after
    # the buffer ("Semaphore or Lock `<_io.BytesIO ...>` not known"); the fake runners of the
    # other tests write no run file, so only a real worker process shows it
    from distributed import Client, LocalCluster

    import xarray as xr

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        out = client.submit(_write_tiny_run_file, tmp_path / "r.nc").result(timeout=120)
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert list(ds["x"].values) == [0.0, 1.0, 2.0, 3.0, 4.0]
