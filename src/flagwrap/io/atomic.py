"""Atomic file creation: write a temporary file beside the target, fsync it, rename it over.

A reader (or a process restarted after ``kill -9``) sees either the old file or the complete
new one, never a half-written file under the final name. Used for run files, checkpoints,
sweep rows and tables, and cached critical-search results.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path


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


def atomic_write(path, write, sync_dir: bool = False) -> Path:
    """Create ``path`` atomically; ``write(tmp)`` must write the whole file at ``tmp`` (a Path).

    The temporary file lives in the target folder (``os.replace`` is atomic only within one
    file system), is fsynced before the rename and removed if ``write`` fails.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        write(Path(tmp))
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, path)
        if sync_dir:
            fsync_dir(path.parent)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path
