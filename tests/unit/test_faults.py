"""Faults during a run: a real file-size limit at a checkpoint write and at the final write,
an output folder that cannot be written.

Oracle: the uninterrupted run of the same config (the loop is deterministic: see
tests/unit/test_checkpoint.py), compared with ``np.array_equal``. Under ``RLIMIT_FSIZE`` no
file above the limit can be written anywhere (the rescue copy in the temporary folder fails
too), so what is kept is the last checkpoint that fitted; the run must say so, exit 1, and
that checkpoint must hold exactly the uninterrupted run's frames up to its step and resume
to the uninterrupted run.
"""

from __future__ import annotations

import os
import re
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

from flagwrap.io.checkpoint import read_checkpoint
from flagwrap.io.config import config_from_dict, tomllib
from flagwrap.io.runfile import write_run
from flagwrap.simulation import simulate

from conftest import tiny_toml

TEXT = tiny_toml(ccw=0.5, cw=1.0)


def _cfg(max_steps=None):
    text = TEXT if max_steps is None else TEXT.replace("[numerics]", f"[numerics]\nmax_steps = {max_steps}")
    return config_from_dict(tomllib.loads(text), name="tiny")


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The uninterrupted run, its run file's size, and the size of a checkpoint at step k."""
    d = tmp_path_factory.mktemp("faults")
    ref = simulate(_cfg())
    write_run(ref, d / "ref.nc")

    def checkpoint_size(k):
        ck = d / f"ck{k}.h5"
        simulate(_cfg(max_steps=k), checkpoint_path=ck, checkpoint_every_steps=k)
        assert read_checkpoint(ck).n_steps == k
        return ck.stat().st_size

    return ref, (d / "ref.nc").stat().st_size, checkpoint_size, d / "ref.nc"


def _run_limited(tmp_path, limit, every):
    cfg = tmp_path / "tiny.toml"
    cfg.write_text(TEXT)
    out, ck = tmp_path / "out.nc", tmp_path / "out.ckpt.h5"

    def cap():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    rescued = set(Path(tempfile.gettempdir()).glob("flagwrap-rescued-out-*"))
    r = subprocess.run([sys.executable, "-m", "flagwrap.cli.main", "run", str(cfg), "-o", str(out), "--quiet",
                        "--checkpoint", str(ck), "--checkpoint-every", str(every)],
                       capture_output=True, text=True, timeout=300, preexec_fn=cap)
    assert set(Path(tempfile.gettempdir()).glob("flagwrap-rescued-out-*")) == rescued  # no empty rescue
    return r, out, ck


def _assert_kept_prefix(ck, ref, k):
    """The checkpoint holds step k and exactly the uninterrupted run's frames up to it, and
    resumes to the uninterrupted run."""
    state = read_checkpoint(ck)
    assert state.n_steps == k
    A = ref.arrays()
    n = len(state.records["t"]) if "t" in state.records else len(next(iter(state.records.values())))
    assert 0 < n < len(next(iter(A.values())))
    for key, v in state.records.items():
        assert np.array_equal(v, A[key][:n]), key
    again = simulate(_cfg(), resume=ck)
    B = again.arrays()
    assert again.n_steps == ref.n_steps and again.n_rejected == ref.n_rejected
    for key in A:
        assert np.array_equal(A[key], B[key]), key


def test_a_file_size_limit_at_a_checkpoint_write_keeps_the_last_checkpoint_that_fitted(tmp_path, reference):
    ref, run_size, checkpoint_size, _ = reference
    k = ref.n_steps // 4
    s1, s2 = checkpoint_size(k), checkpoint_size(2 * k)
    limit = (s1 + s2) // 2  # the checkpoint at k fits, the one at 2k and the run file do not
    assert s1 < limit < s2 < run_size
    r, out, ck = _run_limited(tmp_path, limit, k)
    assert r.returncode == 1 and "Traceback" not in r.stderr, r.stderr
    assert "checkpoint not written" in r.stderr  # the failed checkpoint write was said
    last = r.stderr.strip().splitlines()[-1]
    assert re.search(rf"could not write the run file to {re.escape(str(out))} \(File too large\)", last), last
    assert f"is kept in the checkpoint {ck}" in last and f"({k} steps)" in last, last
    assert not out.exists() and not list(tmp_path.glob("*.lock")) and not list(tmp_path.glob(".*.tmp"))
    _assert_kept_prefix(ck, ref, k)


def test_a_file_size_limit_at_the_final_write_keeps_the_checkpoint(tmp_path, reference):
    ref, run_size, checkpoint_size, _ = reference
    k = ref.n_steps // 2 + 1  # one checkpoint, at k: every checkpoint write succeeds
    s1 = checkpoint_size(k)
    limit = (s1 + run_size) // 2
    assert s1 < limit < run_size
    r, out, ck = _run_limited(tmp_path, limit, k)
    assert r.returncode == 1 and "Traceback" not in r.stderr, r.stderr
    assert "checkpoint not written" not in r.stderr
    lines = [ln for ln in r.stderr.strip().splitlines() if "error" in ln]
    assert len(lines) == 1, r.stderr  # the run's header, then this one line
    assert re.search(rf"could not write the run file to {re.escape(str(out))} \(File too large\) nor to \S+ "
                     rf"\(File too large\); the run up to t/T = [0-9.]+ \({k} steps\) is kept in the checkpoint "
                     rf"{re.escape(str(ck))} \(--resume continues", lines[0]), lines[0]
    assert not out.exists()
    _assert_kept_prefix(ck, ref, k)


def test_a_read_only_output_folder_is_refused_before_any_work(tmp_path):
    if os.geteuid() == 0:
        pytest.skip("root ignores folder permissions; test_cli_hostile simulates the refusal, and "
                    "test_a_final_write_into_a_folder_that_became_read_only_is_kept covers the write")
    (tmp_path / "tiny.toml").write_text(TEXT)
    ro = tmp_path / "ro"
    ro.mkdir()
    (ro / "old.nc").write_bytes(b"an earlier result")
    ro.chmod(0o555)
    try:
        r = subprocess.run([sys.executable, "-m", "flagwrap.cli.main", "run", str(tmp_path / "tiny.toml"),
                            "-o", str(ro / "old.nc"), "--quiet"], capture_output=True, text=True, timeout=300)
        assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
        assert len(r.stderr.strip().splitlines()) == 1 and "cannot write in" in r.stderr, r.stderr
        assert (ro / "old.nc").read_bytes() == b"an earlier result" and sorted(os.listdir(ro)) == ["old.nc"]
    finally:
        ro.chmod(0o755)


def test_a_final_write_into_a_folder_that_became_read_only_is_kept(tmp_path, monkeypatch, capsys, reference):
    # the folder passed the check at the start and is read-only by the end (an administrator, a
    # remount): the write fails with EACCES (simulated where it happens, so that root sees it
    # too); the run is kept in the temporary folder, bit-identical, and the message names it
    from flagwrap.cli.main import main
    from flagwrap.io import runfile

    ref = reference[0]
    real = runfile.write_run
    target = tmp_path / "out.nc"

    def read_only(traj, path):
        if Path(path).parent == tmp_path:
            raise PermissionError(13, "Permission denied", str(path))
        return real(traj, path)

    (tmp_path / "tiny.toml").write_text(TEXT)
    monkeypatch.setattr(runfile, "write_run", read_only)
    code = main(["run", str(tmp_path / "tiny.toml"), "-o", str(target), "--quiet", "--no-checkpoint"])
    err = capsys.readouterr().err
    assert code == 1 and "Permission denied" in err and "is kept in" in err, err
    kept = Path(re.search(r"is kept in (\S+)", err).group(1))
    try:
        from flagwrap.io.runfile import read_run

        ds, want = read_run(kept), read_run(reference[3])  # the uninterrupted run's file
        assert ds.attrs["status"] == "completed" and int(ds.attrs["n_steps"]) == ref.n_steps
        assert set(ds.variables) == set(want.variables)
        for var in want.variables:
            assert np.array_equal(ds[var].values, want[var].values), var
    finally:
        kept.unlink()
    assert not target.exists()
