"""Checkpoint and resume: a run killed with SIGKILL and resumed equals the uninterrupted run.

Oracle: the uninterrupted run of the same config in the same environment. The time loop is
deterministic (numba kernels, single-thread BLAS via ``numerics.threads = 1``) and the
checkpoint holds its complete state (t, y, the reference frames the forces were computed
against, the step-size controller's ``h``, the next output time, counters, the frames recorded
so far), so the comparison is exact: ``np.array_equal``, no tolerance.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import h5py
import numpy as np
import pytest

from flagwrap.cli.main import main
from flagwrap.errors import UserInputError
from flagwrap.io.checkpoint import CHECKPOINT_FORMAT, read_checkpoint
from flagwrap.io.config import config_from_dict, tomllib
from flagwrap.io.runfile import read_run
from flagwrap.simulation import simulate

from conftest import tiny_toml

# ~700 accepted steps (~2-3 s): long enough to be killed mid-way, short enough for CI
LONG = tiny_toml(ccw=0.2, cw=2.0)
VARS = ("time", "position", "twist_angle", "director", "motor_angle", "omega", "motor_torque",
        "elastic_energy", "contact_energy", "min_body_distance", "max_bond_strain")


def _assert_same_run(a, b):
    for v in VARS:
        assert np.array_equal(a[v].values, b[v].values), v
    for k in ("status", "n_steps", "n_rejected", "config_toml", "message"):
        assert a.attrs[k] == b.attrs[k], k


def test_kill_9_then_resume_is_bit_identical(tmp_path):
    cfg = tmp_path / "long.toml"
    cfg.write_text(LONG)
    out = tmp_path / "killed.nc"
    ck = tmp_path / "killed.ckpt.h5"
    proc = subprocess.Popen(
        [sys.executable, "-m", "flagwrap.cli.main", "run", str(cfg), "-o", str(out), "--quiet",
         "--checkpoint", str(ck), "--checkpoint-every", "25"],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    while not ck.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.002)
    time.sleep(0.05)  # let it run a little past the first checkpoint
    assert proc.poll() is None, "run finished before it could be killed: " + proc.stderr.read().decode()
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)
    assert proc.returncode == -signal.SIGKILL
    assert not out.exists()  # no run file yet, only the checkpoint
    state = read_checkpoint(ck)
    assert 0 < state.n_steps and state.n_steps % 25 == 0

    # resume (same options) and compare with an uninterrupted run
    rc = main(["run", str(cfg), "-o", str(out), "--quiet", "--checkpoint", str(ck),
               "--checkpoint-every", "25", "--resume"])
    assert rc == 0
    assert not ck.exists()  # removed once the run completed
    ref = tmp_path / "ref.nc"
    assert main(["run", str(cfg), "-o", str(ref), "--quiet"]) == 0
    a, b = read_run(out), read_run(ref)
    assert state.n_steps < int(b.attrs["n_steps"])  # it really was killed mid-way
    _assert_same_run(a, b)


def test_resume_in_process_from_every_checkpoint_time(tmp_path):
    """Checkpoints at several step counts (including one inside a rejected-step streak) resume exactly."""
    cfg = config_from_dict(tomllib.loads(tiny_toml(ccw=0.2, cw=0.5)))
    ref = simulate(cfg)
    for every in (1, 7, 50):
        ck = tmp_path / f"c{every}.h5"
        simulate(cfg, checkpoint_path=ck, checkpoint_every_steps=every)
        state = read_checkpoint(ck)
        again = simulate(cfg, resume=ck)
        assert again.n_steps == ref.n_steps and again.n_rejected == ref.n_rejected
        A, B = ref.arrays(), again.arrays()
        for k in A:
            assert np.array_equal(A[k], B[k]), (every, k)
        assert state.n_steps == (ref.n_steps // every) * every


@pytest.mark.parametrize("option", ['linear_solver = "krylov"', 'frame = "rotating"'])
def test_resume_is_bit_identical_with_the_iterative_solver_and_in_the_turning_frame(tmp_path, option):
    """The GCR path keeps no state across steps (its recycled directions live in one step),
    so a resumed run must equal the uninterrupted one bit for bit as with the dense LU. In the
    turning frame the checkpoint holds that frame's state and reference frames, and the resumed
    run rebuilds the same turning-frame system."""
    cfg = config_from_dict(tomllib.loads(
        tiny_toml(ccw=0.1, cw=0.1).replace("[numerics]", f"[numerics]\n{option}")))
    key, value = (v.strip().strip('"') for v in option.split("="))
    assert getattr(cfg.numerics, key) == value
    _assert_resume_identical(cfg, tmp_path)


def _assert_resume_identical(cfg, tmp_path):
    """Run ``cfg`` whole, then with a checkpoint every 7 steps resumed from the last one:
    every record equal, bit for bit; returns the records."""
    ref = simulate(cfg)
    ck = tmp_path / "k.h5"
    simulate(cfg, checkpoint_path=ck, checkpoint_every_steps=7)
    again = simulate(cfg, resume=ck)
    assert again.n_steps == ref.n_steps and again.n_rejected == ref.n_rejected
    A, B = ref.arrays(), again.arrays()
    assert set(A) == set(B)
    for k in A:
        assert np.array_equal(A[k], B[k]), k
    return A


def test_a_run_stopped_by_its_step_budget_resumes_with_a_larger_one(tmp_path):
    """max_steps / max_wall_time are budgets of one invocation: the stop writes a checkpoint
    there, resume accepts the config with a larger budget, and the result is bit-identical to
    the uninterrupted run (the budgets do not enter the trajectory)."""
    text = tiny_toml(ccw=0.2, cw=0.5)
    ref = simulate(config_from_dict(tomllib.loads(text)))
    small = config_from_dict(tomllib.loads(text.replace("[numerics]", "[numerics]\nmax_steps = 60")))
    ck = tmp_path / "b.h5"
    cut = simulate(small, checkpoint_path=ck, checkpoint_every_steps=1000)
    assert cut.status == "failed" and read_checkpoint(ck).n_steps == 60
    again = simulate(config_from_dict(tomllib.loads(text)), resume=ck)
    assert again.status == "completed" and again.n_steps == ref.n_steps
    A, B = ref.arrays(), again.arrays()
    for k in A:
        assert np.array_equal(A[k], B[k]), k


def test_checkpoint_by_wall_time(tmp_path):
    cfg = config_from_dict(tomllib.loads(tiny_toml(ccw=0.1, cw=0.1)))
    ck = tmp_path / "s.h5"
    simulate(cfg, checkpoint_path=ck, checkpoint_every_seconds=1e-9)  # every step
    assert read_checkpoint(ck).n_steps > 0


@pytest.fixture
def checkpoint(tmp_path):
    cfg = config_from_dict(tomllib.loads(tiny_toml(ccw=0.1, cw=0.1)))
    ck = tmp_path / "c.h5"
    simulate(cfg, checkpoint_path=ck, checkpoint_every_steps=5)
    return cfg, ck


def test_resume_refuses_other_config(checkpoint, tmp_path):
    cfg, ck = checkpoint
    other = tmp_path / "other.toml"
    other.write_text(tiny_toml(ccw=0.1, cw=0.1, machin=120))
    r = subprocess.run([sys.executable, "-m", "flagwrap.cli.main", "run", str(other), "--quiet",
                        "--checkpoint", str(ck), "--resume", "-o", str(tmp_path / "o.nc")],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert "different config" in r.stderr and "machin" in r.stderr


def test_resume_refuses_other_version_and_damaged_files(checkpoint, tmp_path):
    cfg, ck = checkpoint
    with h5py.File(ck, "r+") as f:
        f.attrs["flagwrap_version"] = "0.0.1"
    with pytest.raises(UserInputError, match="written by flagwrap 0.0.1"):
        simulate(cfg, resume=ck)
    with h5py.File(ck, "r+") as f:
        f.attrs["checkpoint_format"] = 99
    with pytest.raises(UserInputError, match="checkpoint format 99"):
        read_checkpoint(ck)
    data = ck.read_bytes()
    trunc = tmp_path / "trunc.h5"
    trunc.write_bytes(data[: len(data) // 2])
    with pytest.raises(UserInputError, match="not a readable checkpoint"):
        read_checkpoint(trunc)
    with pytest.raises(UserInputError, match="no checkpoint"):
        read_checkpoint(tmp_path / "missing.h5")
    runfile = tmp_path / "notckpt.h5"
    with h5py.File(runfile, "w") as f:
        f.attrs["format"] = "something else"
    with pytest.raises(UserInputError, match="not a flagwrap checkpoint"):
        read_checkpoint(runfile)
    with h5py.File(runfile, "w") as f:
        f.attrs["format"] = "flagwrap checkpoint"
        f.attrs["checkpoint_format"] = CHECKPOINT_FORMAT
    with pytest.raises(UserInputError, match="incomplete or damaged"):
        read_checkpoint(runfile)


def test_resume_without_checkpoint_is_a_clean_error(tmp_path):
    cfgp = tmp_path / "t.toml"
    cfgp.write_text(tiny_toml())
    assert main(["run", str(cfgp), "--quiet", "--resume", "-o", str(tmp_path / "o.nc")]) == 2


def test_checkpoint_records_are_the_trajectory_records():
    from flagwrap.io.checkpoint import RECORD_NAMES
    from flagwrap.simulation import _RECORDS

    assert RECORD_NAMES == _RECORDS


def test_a_checkpoint_from_before_the_joint_records_is_named_as_such(checkpoint):
    # format 1 had no hook/interaction records: refused by its format, not as "damaged"
    cfg, ck = checkpoint
    with h5py.File(ck, "r+") as f:
        f.attrs["checkpoint_format"] = 1
    with pytest.raises(UserInputError, match="checkpoint format 1; this flagwrap .* reads format 3"):
        read_checkpoint(ck)


def test_a_checkpoint_from_before_the_solver_memory_is_named_as_such(checkpoint):
    # format 2 had no solver_memory (a no-slip body's lagged screening): a resume from it
    # would not reproduce the run, so it is refused by its format
    cfg, ck = checkpoint
    with h5py.File(ck, "r+") as f:
        f.attrs["checkpoint_format"] = 2
        del f["solver_memory"]
    with pytest.raises(UserInputError, match="checkpoint format 2; this flagwrap .* reads format 3"):
        read_checkpoint(ck)



@pytest.mark.parametrize("frame", ["lab", "rotating"])
def test_resume_is_bit_identical_for_a_free_swimmer(tmp_path, frame):
    """A free cell's checkpoint holds its pose (in y) and the body records: the resumed run
    equals the uninterrupted one, body pose and velocities included, in the body's frame and
    in the motor's."""
    text = tiny_toml(ccw=0.05, cw=0.05).replace("[numerics]\n", f"[numerics]\nframe = '{frame}'\n")
    cfg = config_from_dict(tomllib.loads(
        text + "\n[body]\nsurface = 'no-slip'\nmotion = 'free'\nblob_spacing = 0.025\n"))
    assert "body" in _assert_resume_identical(cfg, tmp_path)


def test_resume_is_bit_identical_on_a_fixed_no_slip_body(tmp_path):
    """The stage solver's lagged screening is in the checkpoint (solver_memory): the resumed
    run steps with the same W as the uninterrupted one. 80 steps, the screening recomputed 5
    times, the last checkpoint at step 77: it holds a screening from neither end."""
    cfg = config_from_dict(tomllib.loads(
        tiny_toml(ccw=0.2, cw=0.1) + "\n[body]\nsurface = 'no-slip'\nblob_spacing = 0.025\n"))
    A = _assert_resume_identical(cfg, tmp_path)
    mem = read_checkpoint(tmp_path / "k.h5").solver_memory.reshape(-1, 3)
    for k in (0, -1):
        assert not np.allclose(mem, A["x"][k][-len(mem):], rtol=0, atol=1e-6)


def test_resume_is_bit_identical_for_a_free_cell_with_two_torque_speed_flagella(tmp_path):
    """Several flagella: the checkpoint holds every motor's angle (in y) and the per-motor
    records; the resumed run equals the uninterrupted one."""
    text = tiny_toml(ccw=0.05, cw=0.05).replace(
        "[motor]\n", "[motor]\nkind = 'torque-speed'\nstall_torque = 2e-4\nzero_load_speed = 0.05\n")
    text = text.replace("machin = 100", "frequency = 0.02")
    text += ("\n[body]\nsurface = 'no-slip'\nmotion = 'free'\nblob_spacing = 0.025\n"
             "[[flagellum]]\npolar_deg = 35\n[[flagellum]]\npolar_deg = 35\nazimuth_deg = 150\n")
    A = _assert_resume_identical(config_from_dict(tomllib.loads(text)), tmp_path)
    assert "motors" in A and A["motors"].shape[1] == 4 and "body" in A


@pytest.mark.parametrize("boundary", [
    "[[tube]]\nradius = 0.07\nlength = 0.7\ncenter = [0.0, 0.0, -0.1]\nblob_spacing = 0.05\n",
    "[[wall]]\npoint = [0.08, 0.0, 0.0]\nnormal = [-1.0, 0.0, 0.0]\n",
], ids=["tube", "wall"])
def test_resume_is_bit_identical_for_a_free_cell_beside_a_boundary(tmp_path, boundary):
    """Beside a tube or a wall the body's blob solve starts from a factor at a reference pose
    (flagwrap.body.boundaries.ReferenceFactor): the checkpoint holds that pose with the lagged
    screening, so the resumed run solves as the uninterrupted one. The checkpoint's
    reference is not the start's: the factor was rebuilt as the body moved."""
    text = tiny_toml(ccw=0.1, cw=0.1)
    cfg = config_from_dict(tomllib.loads(
        text + "\n[body]\nsurface = 'no-slip'\nmotion = 'free'\nblob_spacing = 0.025\n"
        + boundary))
    assert "body" in _assert_resume_identical(cfg, tmp_path)
    mem = read_checkpoint(tmp_path / "k.h5").solver_memory
    # [X, q], its length; the state's quaternion is used normalised and drifts from unit
    # length by the step's error (measured 1.3e-5 beside the wall)
    assert mem[-1] == 7 and abs(np.linalg.norm(mem[-5:-1]) - 1.0) < 1e-3
    assert np.any(mem[-8:-5] != 0.0)
