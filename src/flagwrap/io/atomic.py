"""Atomic file creation: write a temporary file beside the target, fsync it, rename it over.

A reader (or a process restarted after ``kill -9``) sees either the old file or the complete
new one, never a half-written file under the final name. Used for run files, checkpoints,
sweep rows and tables, and cached critical-search results.

Temporary names are ``.<target>.<host>.<pid>.<random>.tmp``. A writer killed mid-write leaves
one behind; the next :func:`atomic_write` of the same target removes those of dead processes
on the same host (never a live writer's, never another host's).
"""

from __future__ import annotations

import glob
import os
import socket
import tempfile
from pathlib import Path


def _host() -> str:
    return "".join(c if c.isalnum() or c == "-" else "_" for c in socket.gethostname())[:40] or "host"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def _is_stale(tmp: Path, host: str) -> bool:
    """A temporary ``.<target>.<host>.<pid>.<random>.tmp`` whose writer is gone: same host and
    a dead pid, or a name without host/pid (written before temporaries carried them)."""
    parts = tmp.name[1:-len(".tmp")].rsplit(".", 3)
    if len(parts) == 4 and parts[2].isdigit():
        pid = int(parts[2])
        return parts[1] == host and pid != os.getpid() and not _alive(pid)
    return True


def remove_stale_temporaries(path=None, folder=None) -> list[Path]:
    """Delete the temporaries left by dead writers on this host, of the target ``path`` or of
    every target in ``folder``; never a live writer's or another host's. Returns them."""
    host = _host()
    if path is not None:
        path = Path(path)
        candidates = path.parent.glob(f".{glob.escape(path.name)}.{glob.escape(host)}.*.tmp")
    else:
        candidates = Path(folder).glob(".*.tmp")
    removed = []
    for tmp in candidates:
        if _is_stale(tmp, host):
            try:
                tmp.unlink()
                removed.append(tmp)
            except FileNotFoundError:  # another process cleaned it first
                pass
    return removed


def fsync_dir(path) -> None:
    """Flush a directory entry (makes a completed rename durable on POSIX)."""
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:  # pragma: no cover - platforms without directory fds
        return
    try:
        os.fsync(fd)
    except OSError:  # pragma: no cover
        pass
    finally:
        os.close(fd)


def _read_umask() -> int:
    # read once at import (setting it back and forth is not thread-safe later on)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


_UMASK = _read_umask()


def atomic_write(path, write, sync_dir: bool = False) -> Path:
    """Create ``path`` atomically; ``write(tmp)`` must write the whole file at ``tmp`` (a Path).

    The temporary file lives in the target folder (``os.replace`` is atomic only within one
    file system), is fsynced before the rename and removed if ``write`` fails.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    remove_stale_temporaries(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.{_host()}.{os.getpid()}.", suffix=".tmp",
                               dir=path.parent)
    os.close(fd)
    try:
        write(Path(tmp))
        # mkstemp makes the file 0600; the result gets the mode a plain open() would give
        os.chmod(tmp, 0o666 & ~_UMASK)
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
        if sync_dir:
            fsync_dir(path.parent)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


#: files up to this size are built in memory and written as bytes (:func:`write_image`)
IMAGE_MAX = 1 << 30


def write_image(path, build, size_hint: int = 0, sync_dir: bool = False) -> Path:
    """Create ``path`` atomically from an HDF5 file that ``build(target)`` writes: into memory
    (an ``io.BytesIO``), then its bytes to the temporary file, when ``size_hint`` is at most
    :data:`IMAGE_MAX`; straight to the temporary file otherwise.

    Why: HDF5 fails badly when the disk fills or a file-size limit (``ulimit -f``) stops a
    write inside it: h5py raises from a destructor and the process dies by a signal (measured:
    exit -11, nothing kept). Built in memory, the file's bytes reach the disk by plain writes,
    whose failure is a clean ``OSError`` (ENOSPC, EFBIG) that the callers report and rescue."""
    if size_hint > IMAGE_MAX:
        return atomic_write(path, build, sync_dir=sync_dir)
    import io

    buf = io.BytesIO()
    build(buf)
    data = buf.getbuffer()
    return atomic_write(path, lambda tmp: tmp.write_bytes(data), sync_dir=sync_dir)


def read_error(path, what: str, exc: BaseException) -> str:
    """One-line message for a file that could not be read: a failed checksum (HDF5's
    Fletcher-32 filter reports "filter returned failure" / "checksum") is called corrupt, any
    other error unreadable (truncated, not HDF5)."""
    text = " ".join(str(exc).split())  # one line
    low = text.lower()
    if "filter returned failure" in low or "checksum" in low or "differ from their checksummed" in low:
        return (f"{path} is corrupt: it fails its checksum ({text}); the file is left as it "
                f"is, re-create it")
    return f"{path} is not a readable {what} (truncated, damaged or not netCDF4/HDF5): {text}"


def savefig_atomic(fig, path, **kwargs) -> Path:
    """``fig.savefig`` into a temporary file beside ``path`` (same suffix, so matplotlib picks
    the format) and renamed in: an existing figure is replaced only by a complete one."""
    path = Path(path)

    def write(tmp):
        fig.savefig(tmp, format=path.suffix.lstrip(".").lower() or None, **kwargs)

    return atomic_write(path, write)
