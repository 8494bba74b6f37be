"""Output paths checked before any work, and one writer per output.

Every command that writes calls :func:`check_output_file` / :func:`check_output_dir` for each
of its targets before it computes anything, so a bad target (an existing directory where a
file goes, a parent that is a file, a folder that cannot be written, an unknown suffix, too
little free space) is a one-line :class:`~flagwrap.errors.UserInputError` (exit 2) instead of
a traceback after the work. :func:`output_lock` refuses a second process writing the same
run file or checkpoint (an advisory ``fcntl``/``msvcrt`` lock through the ``filelock``
package, released by the operating system when the holder dies, so a killed run never leaves
a stale lock). :func:`write_or_rescue` writes a finished result and, if the final write fails
(disk full, folder gone), puts it in the temporary folder and names it.
"""

from __future__ import annotations

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path

from flagwrap.errors import OutputWriteError, UserInputError


def _existing_ancestor(p: Path) -> Path:
    """The nearest existing folder at or above ``p``'s parent (or a file blocking the path)."""
    d = p.parent
    while not d.exists() and d != d.parent:
        d = d.parent
    return d


def _probe_writable(folder: Path, what: str, target: Path) -> None:
    """Create and remove a file in ``folder`` (``os.access`` says yes to root on read-only
    mounts and to ACL-denied folders)."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=".flagwrap-probe.", dir=folder)
        os.close(fd)
        os.unlink(tmp)
    except OSError as exc:
        raise UserInputError(f"{what} {target}: cannot write in {folder} ({exc.strerror or exc})") from None


def check_output_file(path, what: str = "output", suffixes=None) -> Path:
    """Raise :class:`UserInputError` unless ``path`` can be written as a file.

    ``suffixes``: allowed suffixes (lower case, with the dot), or None for any. Creates
    nothing; a run's free space is :func:`flagwrap.resources.check_disk`'s.
    """
    p = Path(path)
    if str(path).strip() == "":
        raise UserInputError(f"{what}: empty path")
    if p.is_dir():
        raise UserInputError(f"{what} {p} is an existing directory; give a file name")
    if suffixes is not None and p.suffix.lower() not in suffixes:
        raise UserInputError(f"{what} {p}: unknown suffix {p.suffix or '(none)'!r}; allowed: "
                             f"{', '.join(sorted(suffixes))}")
    anc = _existing_ancestor(p)
    if not anc.is_dir():
        raise UserInputError(f"{what} {p}: {anc} is a file, not a folder")
    _probe_writable(anc, what, p)
    return p


def check_output_dir(path, what: str = "output folder") -> Path:
    """Raise :class:`UserInputError` unless ``path`` is (or can be created as) a writable folder."""
    p = Path(path)
    if str(path).strip() == "":
        raise UserInputError(f"{what}: empty path")
    if p.exists() and not p.is_dir():
        raise UserInputError(f"{what} {p} is an existing file, not a folder")
    anc = p if p.is_dir() else _existing_ancestor(p / "x")
    if not anc.is_dir():
        raise UserInputError(f"{what} {p}: {anc} is a file, not a folder")
    _probe_writable(anc, what, p)
    return p


@contextmanager
def output_lock(*paths):
    """Hold ``<path>.lock`` for each path (None entries skipped) while the block runs; another
    process holding one is a :class:`UserInputError` naming it."""
    from filelock import FileLock, Timeout

    held = []
    try:
        for p in paths:
            if p is None:
                continue
            lock_path = Path(f"{p}.lock")
            lock_path.parent.mkdir(parents=True, exist_ok=True)
            stale = lock_path.exists()
            lock = FileLock(str(lock_path), timeout=0)
            try:
                lock.acquire()
            except Timeout:
                raise UserInputError(f"another flagwrap process is writing {p} (it holds {lock_path}); "
                                     "wait for it to finish or choose another output") from None
            if stale:  # the file was there but no process held it: one that was killed
                import sys

                print(f"flagwrap: note: {lock_path} was left by a process that is gone; taken over",
                      file=sys.stderr)
            held.append((lock, lock_path))
        yield
    finally:
        for lock, lock_path in reversed(held):
            lock.release()
            try:
                lock_path.unlink()
            except OSError:
                pass


def write_or_rescue(write, path, what: str = "result"):
    """``write(path)``; if it raises ``OSError``, ``write`` into a new file in the temporary
    folder instead and raise :class:`~flagwrap.errors.OutputWriteError` naming both (the result is kept)."""
    path = Path(path)
    try:
        return write(path)
    except OSError as exc:
        fd, rescue = tempfile.mkstemp(prefix=f"flagwrap-rescued-{path.stem}-", suffix=path.suffix)
        os.close(fd)
        try:
            write(Path(rescue))
        except OSError as exc2:
            Path(rescue).unlink(missing_ok=True)
            raise OutputWriteError(f"could not write the {what} to {path} ({exc.strerror or exc}) "
                                 f"nor to {rescue} ({exc2.strerror or exc2}); it is lost") from None
        raise OutputWriteError(f"could not write the {what} to {path} ({exc.strerror or exc}); it "
                             f"is kept in {rescue}") from None
