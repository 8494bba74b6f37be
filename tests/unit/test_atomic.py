"""Atomic writes: complete file or none; temporaries of dead writers are cleaned up."""

import os
import subprocess
import sys

from flagwrap.io.atomic import _host, atomic_write, remove_stale_temporaries


def _dead_pid():
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def test_stale_temporaries_of_dead_writers_are_removed_live_ones_kept(tmp_path):
    target = tmp_path / "row.json"
    host = _host()
    dead = tmp_path / f".row.json.{host}.{_dead_pid()}.abc123.tmp"
    live = tmp_path / f".row.json.{host}.{os.getppid()}.def456.tmp"  # the test runner's parent
    other_host = tmp_path / f".row.json.otherhost.{_dead_pid()}.ghi789.tmp"
    other_target = tmp_path / f".row2.json.{host}.{_dead_pid()}.jkl012.tmp"
    for f in (dead, live, other_host, other_target):
        f.write_text("partial")
    atomic_write(target, lambda tmp: tmp.write_text('{"ok": 1}'))
    assert target.read_text() == '{"ok": 1}'
    assert not dead.exists()
    assert live.exists() and other_host.exists() and other_target.exists()
    assert remove_stale_temporaries(target) == []


def test_failed_write_leaves_neither_target_nor_temporary(tmp_path):
    target = tmp_path / "run.nc"

    def boom(tmp):
        tmp.write_text("half")
        raise RuntimeError("disk full")

    try:
        atomic_write(target, boom)
    except RuntimeError:
        pass
    assert not target.exists()
    assert list(tmp_path.iterdir()) == []


def test_sweep_store_clean_spares_live_writers(tmp_path):
    from flagwrap.sweep.store import SweepStore

    store = SweepStore(tmp_path)
    store.rows.mkdir(parents=True)
    host = _host()
    dead = store.rows / f".k1.json.{host}.{_dead_pid()}.aaaa1111.tmp"
    legacy = store.rows / ".k2.json.bbbb2222.tmp"  # written before names carried host/pid
    live = store.rows / f".k3.json.{host}.{os.getppid()}.cccc3333.tmp"
    remote = store.rows / f".k4.json.otherhost.{_dead_pid()}.dddd4444.tmp"
    for f in (dead, legacy, live, remote):
        f.write_text("partial")
    assert store.clean() == 2
    assert not dead.exists() and not legacy.exists() and live.exists() and remote.exists()


def test_atomic_files_get_the_mode_of_a_plain_open(tmp_path):
    # mkstemp's 0600 must not leak into results that other users or workers read
    import stat

    plain = tmp_path / "plain.txt"
    plain.write_text("x")
    out = atomic_write(tmp_path / "atomic.txt", lambda tmp: tmp.write_text("x"))
    assert stat.S_IMODE(os.stat(out).st_mode) == stat.S_IMODE(os.stat(plain).st_mode)
