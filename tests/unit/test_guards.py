"""Guards stop a run with a message naming time, bead and quantity; the partial run file keeps
every good frame, marked failed; damaged or foreign run files are reported, not misread.

Oracles: a fixed explicit-Euler step far above the stability limit of the stretching springs
(``h < ~2 M / (k_s mu)``) must blow a bond up within a couple of steps; a guard must never
let a frame that violates it into the file; the run-file reader's contract (``read_run``).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np
import pytest

from flagwrap.errors import UserInputError
from flagwrap.io.config import config_from_dict, tomllib
from flagwrap.io.runfile import read_run, write_run
from flagwrap.resources import check_disk, check_memory, estimate
from flagwrap.simulation import Simulation, simulate

from conftest import tiny_toml

TINY = tiny_toml(ccw=0.3, cw=0.3)


def _cfg(text=TINY, **numerics):
    d = tomllib.loads(text)
    d["numerics"].update(numerics)
    return config_from_dict(d)


def test_too_large_euler_step_stops_with_guard_message_and_partial_file(tmp_path):
    cfgp = tmp_path / "big_dt.toml"
    cfgp.write_text(TINY + 'integrator = "euler"\ndt = 0.05\n')
    out = tmp_path / "big_dt.nc"
    r = subprocess.run([sys.executable, "-m", "flagwrap.cli.main", "run", str(cfgp), "--quiet",
                        "-o", str(out)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 1 and "Traceback" not in r.stderr
    msg = re.search(r"run stopped: (.*) \(partial output kept", r.stderr).group(1)
    # time, bead and quantity
    pattern = r"t/T=[0-9.]+: bond \d+ \(beads \d+-\d+\) strain [0-9.e+]+ exceeds the limit 0.05"
    assert re.match(pattern, msg), msg
    ds = read_run(out)
    assert ds.attrs["status"] == "failed" and ds.attrs["message"] == msg
    # every stored frame is a good one (passed the guard), and the file is complete and readable
    assert len(ds["time"]) >= 2
    assert np.all(ds["max_bond_strain"].values <= 0.05)
    assert np.all(np.isfinite(ds["position"].values))
    t_fail = float(re.match(r"t/T=([0-9.]+)", msg).group(1))
    assert ds["turns"].values[-1] < t_fail


def test_step_size_floor(tmp_path):
    cfg = _cfg(tol=1e-9, dt=0.02, dt_min=0.01)
    traj = simulate(cfg)
    assert traj.status == "failed"
    assert re.match(r"t/T=0: step size [0-9.e-]+ T fell below dt_min=0.01 T \(error above tolerance\); "
                    r"fastest bead \d+ \(\|dx/dt\| = ", traj.message), traj.message
    out = tmp_path / "floor.nc"
    write_run(traj, out)
    ds = read_run(out)
    assert ds.attrs["status"] == "failed" and len(ds["time"]) == 1  # the initial frame


def test_wall_time_budget_stops_the_run_and_keeps_its_frames(tmp_path, monkeypatch):
    # the loop's clock advances 0.05 s per reading, so the 0.5 s budget trips after ~10 steps
    # on any machine (a real clock made this test depend on the machine's speed)
    import itertools

    from flagwrap import simulation

    ticks = itertools.count()
    monkeypatch.setattr(simulation._time, "perf_counter", lambda: 0.05 * next(ticks))
    cfg = _cfg(tol=1e-7, max_wall_time=0.5)
    traj = simulate(cfg)
    assert traj.status == "failed"
    assert re.match(r"t/T=[0-9.e-]+: wall time above numerics.max_wall_time=0.5 s", traj.message), \
        traj.message
    assert 0 < traj.t[-1] < 0.6 * 2 * np.pi and len(traj.t) >= 2
    out = tmp_path / "wall.nc"
    write_run(traj, out)
    assert read_run(out).attrs["status"] == "failed"
    with pytest.raises(UserInputError, match="max_wall_time"):
        _cfg(max_wall_time=-1.0)


@pytest.mark.parametrize("numerics,needle", [
    (dict(max_steps=30), "reached numerics.max_steps=30"),
    (dict(dt=0.002, dt_min=0.0011), "fell below dt_min=0.0011 T"),  # shrinks mid-run
])
def test_a_stopped_run_keeps_its_last_good_state_as_a_frame(numerics, needle):
    # every stop path ends on a good state (t, y): it is the last frame, at the time the
    # message names (printed to 6 digits), not the output time before it
    traj = simulate(_cfg(**numerics))
    assert traj.status == "failed" and needle in traj.message, traj.message
    t_stop = float(re.match(r"t/T=([0-9.e-]+)", traj.message).group(1))
    assert t_stop > 0.06  # past the first output times (save_every 0.05)
    assert traj.t[-1] / (2 * np.pi) == pytest.approx(t_stop, rel=1e-5)


def test_a_run_past_the_protocol_keeps_the_last_motor_speed():
    # Simulation.run(t_end) beyond the protocol: the schedule keeps its last speed there
    sim = Simulation(_cfg())
    t_end = sim.system.schedule.t_end + 0.1 * 2 * np.pi
    traj = sim.run(t_end=t_end)
    assert traj.status == "completed", traj.message
    assert traj.t[-1] == pytest.approx(t_end)
    assert traj.omega[-1] == sim.system.schedule.segments[-1].omega


def test_a_failed_checkpoint_write_warns_and_the_run_goes_on(tmp_path):
    blocker = tmp_path / "not_a_folder"
    blocker.write_text("a file where the checkpoint's folder should be")
    with pytest.warns(RuntimeWarning, match="checkpoint not written"):
        traj = simulate(_cfg(), checkpoint_path=blocker / "ck.h5", checkpoint_every_steps=5)
    assert traj.status == "completed"
    assert np.array_equal(traj.arrays()["x"], simulate(_cfg()).arrays()["x"])


def test_run_budgets_hold_across_chunks_of_the_sweep_runner():
    from flagwrap.analysis.critical import simulate_until_buckled

    cfg = _cfg(tiny_toml(ccw=0.1, cw=3.0), max_steps=400)
    # the CW phase runs in one-turn chunks, each a Simulation.run: 400 steps in all, not each
    traj = simulate_until_buckled(cfg, stop_after=2.0)
    assert traj.status == "failed" and "max_steps=400" in traj.message, traj.message
    assert traj.n_steps == 400


def test_non_finite_force_and_body_entry_guards_name_the_bead():
    cfg = _cfg()
    sim = Simulation(cfg)
    s = sim.system
    y = s.initial_y()
    info = s.forces(y, s.frames0.copy())
    assert sim._guard(info) == ""
    k = 3 * 4 + 1  # free bead 4, y component
    info.G[k] = np.nan
    assert sim._guard(info) == f"non-finite generalized force nan on bead {s.nc + 4} (force component y)"
    info.G[k] = 0.0
    info.G[s.sl_th.start + 2] = np.inf
    assert sim._guard(info) == f"non-finite generalized force inf on bond {s.ec + 2} (twist torque)"
    info.G[s.sl_th.start + 2] = 0.0
    info.distance[7] = -0.01
    assert sim._guard(info) == "bead 7 entered the cell body (distance -0.01 L)"


def test_truncated_and_foreign_run_files_are_reported(tiny_run, tmp_path):
    data = tiny_run.read_bytes()
    for frac in (0.5, 0.9):
        p = tmp_path / f"cut{frac}.nc"
        p.write_bytes(data[: int(len(data) * frac)])
        with pytest.raises(UserInputError, match="truncated"):
            read_run(p)
    # the CLI: one line, exit 2
    r = subprocess.run([sys.executable, "-m", "flagwrap.cli.main", "analyze", str(tmp_path / "cut0.5.nc")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "Traceback" not in r.stderr and "truncated" in r.stderr
    newer = tmp_path / "newer.nc"
    newer.write_bytes(data)
    with h5py.File(newer, "r+") as f:
        f.attrs["format_version"] = 99
    with pytest.raises(UserInputError, match="format_version 99, newer"):
        read_run(newer)
    foreign = tmp_path / "foreign.nc"
    with h5py.File(foreign, "w") as f:
        f["x"] = np.arange(3.0)
    with pytest.raises(UserInputError, match="not a flagwrap run file"):
        read_run(foreign)


def test_resource_guards_name_the_inputs(tmp_path):
    cfg = _cfg()
    est = estimate(cfg)
    assert est.n_saves == pytest.approx(0.6 / 0.05 + 2)
    check_memory(cfg)
    long = config_from_dict({**tomllib.loads(TINY), "motor": {
        "machin": 100, "protocol": [{"direction": "cw", "turns": 1e12}]}})
    with pytest.raises(UserInputError, match="motor.protocol turns.*numerics.save_every"):
        check_memory(long)
    # the dense W (640 MB at 1000 beads) only where the stage solver forms it: "dense", or
    # "auto" up to AUTO_CROSSOVER_NY unknowns; "auto" at 1000 beads is GCR (~6 MB)
    with pytest.raises(UserInputError, match=r"filament.n_beads=1000 \(3993 unknowns\)"):
        check_memory(_cfg(tiny_toml(n_beads=1000), linear_solver="dense"), limit=100e6)
    check_memory(_cfg(tiny_toml(n_beads=1000)), limit=100e6)
    with pytest.raises(UserInputError, match=r"filament.n_beads=90 \(353 unknowns\)"):
        check_memory(_cfg(tiny_toml(n_beads=90)), limit=3e6)  # auto: dense, 5.2 MB
    check_memory(_cfg(tiny_toml(n_beads=90), linear_solver="krylov"), limit=3e6)
    with pytest.raises(UserInputError, match="disk"):
        check_disk(cfg, tmp_path / "o.nc", free=1000.0)
    huge = tmp_path / "huge.toml"
    huge.write_text(TINY.replace("save_every = 0.05", "save_every = 1e-9"))
    r = subprocess.run([sys.executable, "-m", "flagwrap.cli.main", "run", str(huge), "--quiet",
                        "-o", str(tmp_path / "huge.nc")], capture_output=True, text=True,
                       timeout=120, env={**os.environ, "FLAGWRAP_MAX_MEMORY": "1G"})
    assert r.returncode == 2 and "numerics.save_every" in r.stderr and "Traceback" not in r.stderr


@pytest.mark.parametrize("signame, code, said", [("SIGINT", 130, r"SIGINT / Ctrl-C"),
                                                  ("SIGTERM", 143, r"SIGTERM")])
def test_ctrl_c_and_sigterm_keep_a_readable_partial_run_file(tmp_path, signame, code, said):
    # SIGTERM is what `timeout` and batch schedulers send: treated as Ctrl-C (the partial
    # file kept, --resume named, no lock left), exit 128 + the signal's number
    import signal
    import time

    sig = getattr(signal, signame)
    cfgp = tmp_path / "long.toml"
    cfgp.write_text(tiny_toml(ccw=50, cw=50).replace("tol = 1e-3", "tol = 1e-7"))  # minutes of work
    out = tmp_path / "long.nc"
    ckpt = tmp_path / "long.ckpt.h5"
    # the signal back to its default in the child: a test run started in the background
    # (nohup, `cmd &`) inherits SIGINT ignored, and the run then rightly ignores Ctrl-C too
    proc = subprocess.Popen([sys.executable, "-m", "flagwrap.cli.main", "run", str(cfgp), "--quiet",
                             "-o", str(out), "--checkpoint", str(ckpt), "--checkpoint-every", "50"],
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(sig, signal.SIG_DFL))
    # wait until the time loop runs (a checkpoint exists), however long imports and a cold
    # numba cache take, then let it save a few frames
    t0 = time.monotonic()
    while not ckpt.exists() and proc.poll() is None and time.monotonic() - t0 < 300:
        time.sleep(0.2)
    time.sleep(2)
    proc.send_signal(sig)
    # generous: the step in flight, the last frame and the partial file; on a loaded 2-core
    # machine (CI beside other jobs) 60 s was once not enough
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == code, err
    assert "Traceback" not in err
    assert re.search(rf"run stopped: t/T=[0-9.e-]+: interrupted \({said}\) \(partial output kept"
                     r".*--resume continues", err), err
    ds = read_run(out)
    assert ds.attrs["status"] == "failed" and "interrupted" in ds.attrs["message"]
    assert len(ds["time"]) >= 1 and np.all(np.isfinite(ds["position"].values))
    assert not list(tmp_path.glob("*.lock"))  # released and removed
    assert ckpt.exists()


def test_a_rerun_without_resume_says_a_checkpoint_exists_and_a_stale_lock_is_taken_over(tmp_path):
    cfgp = tmp_path / "t.toml"
    cfgp.write_text(tiny_toml(ccw=0.05, cw=0.05))
    out = tmp_path / "t.nc"
    Path(f"{out}.ckpt.h5").write_bytes(b"an earlier run's")
    Path(f"{out}.lock").write_text("")  # left by a killed process: nobody holds it
    r = subprocess.run([sys.executable, "-m", "flagwrap.cli.main", "run", str(cfgp), "--quiet",
                        "-o", str(out)], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert "holds an earlier run's checkpoint; starting over (--resume continues" in r.stderr
    assert f"{out}.lock was left by a process that is gone; taken over" in r.stderr
    assert not list(tmp_path.glob("*.lock"))


def _interrupting_step(sim, n_signals, after=3):
    """Wrap ``sim.integrator.step`` so that its ``after``-th call sends ``n_signals`` SIGINTs to
    this process from inside the step, like a Ctrl-C landing mid-step (``raise_signal`` runs
    the Python handler synchronously, in this thread)."""
    import signal

    if signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        pytest.skip("the test runner owns SIGINT here")
    inner, calls = sim.integrator.step, [0]

    def step(*args, **kwargs):
        calls[0] += 1
        if calls[0] == after:
            for _ in range(n_signals):
                signal.raise_signal(signal.SIGINT)
        return inner(*args, **kwargs)

    sim.integrator.step = step
    return calls


def test_first_ctrl_c_finishes_the_step_and_keeps_its_state():
    """One SIGINT mid-step is deferred to the step's end: the run stops there with the state
    after that step as its last frame, and Python's own SIGINT handler is back afterwards."""
    import signal

    from flagwrap.simulation import RunInterrupted

    sim = Simulation(_cfg())
    calls = _interrupting_step(sim, 1)
    with pytest.raises(RunInterrupted) as exc:
        sim.run()
    traj = exc.value.trajectory
    assert calls[0] == 3  # no step started after the signal
    assert traj.status == "failed" and "interrupted" in traj.message
    assert traj.n_steps + traj.n_rejected == 3
    assert traj.t[-1] > 0 and np.all(np.isfinite(traj.arrays()["x"]))
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_second_ctrl_c_interrupts_inside_the_step():
    """A second SIGINT is not deferred (a step may take seconds at large N): the step is cut,
    and the frames saved before it are kept."""
    import signal

    from flagwrap.simulation import RunInterrupted

    sim = Simulation(_cfg())
    _interrupting_step(sim, 2)
    with pytest.raises(RunInterrupted) as exc:
        sim.run()
    traj = exc.value.trajectory
    assert traj.n_steps + traj.n_rejected == 2  # the third step never finished
    assert traj.t == [0.0]  # no frame from the cut step (nor from the two before: save_every)
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_ctrl_c_in_the_last_step_still_reaches_the_caller():
    """A deferred Ctrl-C that arrives during the step that ends the run must not be lost: the
    run is complete (all frames kept), but the caller (a sweep) is told to stop."""
    from flagwrap.simulation import RunInterrupted

    probe = Simulation(_cfg())
    calls = _interrupting_step(probe, 0)  # count the steps of the run (deterministic)
    probe.run(t_end=0.01)
    last = calls[0]
    sim = Simulation(_cfg())
    _interrupting_step(sim, 1, after=last)
    with pytest.raises(RunInterrupted) as exc:
        sim.run(t_end=0.01)
    traj = exc.value.trajectory
    assert traj.status == "completed" and "during the last step" in traj.message
    assert traj.t[-1] == pytest.approx(0.01)


def test_interrupt_wrapped_by_numba_is_still_an_interrupt():
    """numba reports a KeyboardInterrupt raised while it loads a cached kernel as a
    SystemError (the CI failure this guards against); the run must treat it as Ctrl-C."""
    from flagwrap.simulation import RunInterrupted

    sim = Simulation(_cfg())
    inner, calls = sim.integrator.step, [0]

    def step(*args, **kwargs):
        calls[0] += 1
        if calls[0] == 3:
            try:
                raise KeyboardInterrupt
            except KeyboardInterrupt as ki:
                raise SystemError("CPUDispatcher(...) returned a result with an exception set") from ki
        return inner(*args, **kwargs)

    sim.integrator.step = step
    with pytest.raises(RunInterrupted) as exc:
        sim.run()
    assert "interrupted" in exc.value.trajectory.message
    other = Simulation(_cfg())
    other.integrator.step = lambda *a, **k: (_ for _ in ()).throw(SystemError("genuine"))
    with pytest.raises(SystemError, match="genuine"):  # a real SystemError is not swallowed
        other.run()


def test_a_run_that_stops_at_once_says_when_beads_start_in_contact():
    # 400 beads on the Fig. 4(a) helix: bond 1 mm, so the first free bead starts 1.35 mm from
    # the body, inside the 3 mm contact range, and the repulsion throws it off at t = 0
    with open("examples/fig4a.toml", "rb") as fh:
        d = tomllib.load(fh)
    d["filament"]["n_beads"] = 400
    d["motor"]["protocol"] = [{"direction": "ccw", "turns": 0.01}]
    traj = simulate(config_from_dict(d))
    assert traj.status == "failed"
    assert re.search(r"bead 2 starts 1.35 mm from the cell body, inside its contact range "
                     r"a \(1 \+ contact.range\) = 3 mm: with filament.n_beads = 400", traj.message)
    # a run that starts clear of the body never gets the hint
    assert "contact range" not in simulate(_cfg(max_steps=5)).message


def test_the_start_contact_hint_is_not_given_for_budget_stops():
    with open("examples/fig4a.toml", "rb") as fh:
        d = tomllib.load(fh)
    d["filament"]["n_beads"] = 241  # first free bead 2.25 mm from the body (range 3 mm): runs
    d["motor"]["protocol"] = [{"direction": "ccw", "turns": 0.01}]
    d["numerics"]["max_steps"] = 1
    traj = simulate(config_from_dict(d))
    assert "max_steps=1" in traj.message and "contact range" not in traj.message


def test_the_estimate_prices_a_no_slip_body_and_names_its_spacing():
    # a direct blob solver holds its factor and inverse, two (3 n)^2 matrices: a body of
    # ~1500 blobs costs ~0.3 GB, which the memory check must count (and name) before any work
    import dataclasses

    from flagwrap.body.multiblob import cell_body_blobs
    from flagwrap.errors import UserInputError
    from flagwrap.io.config import load_config
    from flagwrap.resources import check_memory, estimate

    cfg = load_config(Path(__file__).parents[2] / "examples" / "s_putrefaciens.toml")
    est = estimate(cfg)
    n = len(cell_body_blobs(cfg)[0])
    # a triangular lattice over the surface: an upper estimate of the ring-placed blobs
    assert n <= est.blobs <= 1.4 * n
    assert est.blob_memory >= 2 * 8 * (3 * n) ** 2
    fine = cfg.replace(body=dataclasses.replace(cfg.body, solver="direct",
                                                blob_spacing=0.4 * cfg.body.resolved_blob_spacing(
                                                    cfg.filament.helix_radius)))
    with pytest.raises(UserInputError, match=r"the no-slip body: about .* blobs at "
                                             r"body.blob_spacing = .* body.solver = 'direct'"):
        check_memory(fine, limit=0.5 * estimate(fine).blob_memory)
    krylov = fine.replace(body=dataclasses.replace(fine.body, solver="krylov"))
    # the Krylov solver's overlapping blocks (O(n)) and coarse block (9 n^2 / 64 against
    # the direct 18 n^2): 7 % of the direct memory at these ~3600 blobs, less with more
    assert estimate(krylov).blob_memory < 0.15 * estimate(fine).blob_memory


def test_sigterm_stops_a_critical_search_without_a_traceback(tmp_path):
    # `flagwrap critical` under `timeout` or a scheduler's limit: one line naming the signal
    # and the cache it resumes from, exit 143 (it used to end in a RunInterrupted traceback)
    import signal
    import time

    cfgp = tmp_path / "long.toml"
    cfgp.write_text(tiny_toml().replace("tol = 1e-3", "tol = 1e-7"))
    cache = tmp_path / "cache"
    proc = subprocess.Popen([sys.executable, "-m", "flagwrap.cli.main", "critical", str(cfgp),
                             "--cache", str(cache)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGTERM, signal.SIG_DFL))
    t0 = time.monotonic()  # the header is printed once the search starts
    line = proc.stdout.readline()
    assert "critical search" in line, line
    time.sleep(3)
    assert proc.poll() is None  # still searching (tol 1e-7: minutes of work)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 143, err
    assert "Traceback" not in err
    assert re.search(r"interrupted \(SIGTERM\) during a run at t/T=[0-9.]+; the runs finished "
                     rf"before it are cached in {re.escape(str(cache))}", err), err
    assert time.monotonic() - t0 < 300


def test_a_file_size_limit_ends_in_a_message_not_a_crash(tmp_path):
    # issue 33, item 1: HDF5 writing into a full disk / past `ulimit -f` used to kill the
    # process by a signal (exit -11, nothing said); the file is now built in memory and its
    # bytes written plainly, so the failure is an OSError reported in one line, exit 1, and
    # no empty rescue file is left behind
    import resource

    cfgp = tmp_path / "t.toml"
    cfgp.write_text(tiny_toml(ccw=1, cw=1))
    limit = 50 * 1024  # bytes: the run file is ~100 kB

    def cap():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    before = set(Path(tempfile.gettempdir()).glob("flagwrap-rescued-t-*"))
    r = subprocess.run([sys.executable, "-m", "flagwrap.cli.main", "run", str(cfgp), "--quiet",
                        "-o", str(tmp_path / "t.nc"), "--checkpoint", str(tmp_path / "t.ckpt.h5"),
                        "--checkpoint-every", "20"], capture_output=True, text=True,
                       timeout=300, preexec_fn=cap)
    assert r.returncode == 1, r.stderr
    assert "Traceback" not in r.stderr
    assert re.search(r"error: could not write the run file to \S+t\.nc \(File too large\)",
                     r.stderr), r.stderr
    assert not (tmp_path / "t.nc").exists() and not list(tmp_path.glob("*.lock"))
    assert set(Path(tempfile.gettempdir()).glob("flagwrap-rescued-t-*")) == before


def test_analyze_names_a_partial_run_that_stopped_before_the_reversal(tmp_path, capsys):
    from flagwrap.cli.main import main
    from flagwrap.io.runfile import write_dataset_atomic

    cfgp = tmp_path / "t.toml"
    cfgp.write_text(tiny_toml(ccw=0.2, cw=0.2))
    out = tmp_path / "t.nc"
    assert main(["run", str(cfgp), "--quiet", "-o", str(out)]) == 0
    ds = read_run(out)
    part = ds.isel(time=np.flatnonzero(ds["turns"].values <= 0.15))
    part.attrs["status"] = "failed"
    part.attrs["message"] = "t/T=0.15: interrupted (SIGTERM)"
    write_dataset_atomic(part, out)
    capsys.readouterr()
    assert main(["analyze", str(out), "--no-write"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "partial run (t/T=0.15: interrupted (SIGTERM))" in err[0]
    assert "--resume" in err[0]
