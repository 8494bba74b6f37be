"""One sweep case: run it with its case function and form its row (never raises).

Used by :mod:`flagwrap.sweep.runner` (grid mode, through Dask) and by
:mod:`flagwrap.sweep.boundary` (the test runs of a boundary search); kept apart from both so
that neither imports the other.
"""

from __future__ import annotations

import importlib
import socket
import time

from flagwrap.sweep.spec import Case
from flagwrap.sweep.store import SweepStore

DEFAULT_RUNNER = "flagwrap.analysis.critical:simulate_and_analyse"

#: the case functions a sweep file may name: name -> "module:function". A sweep file names
#: one of these, never code to import (a file shared between users must not run code); the
#: user registers more from Python (:func:`register_runner`) or in the environment that runs
#: the command (``FLAGWRAP_SWEEP_RUNNERS="name=module:function,..."``), both theirs.
RUNNERS = {"default": DEFAULT_RUNNER}


def register_runner(name: str, target: str) -> None:
    """Let sweep files name the case function ``target`` ("module:function", importable on
    every worker) as ``runner = name``."""
    if not (isinstance(name, str) and name.replace("-", "_").isidentifier()):
        raise ValueError(f"runner name must be a word (letters, digits, _ or -), got {name!r}")
    mod, sep, fn = str(target).partition(":")
    if not (sep and mod and fn.isidentifier()):
        raise ValueError(f"runner target must be 'module:function', got {target!r}")
    RUNNERS[name] = str(target)


def runner_target(name: str | None) -> str:
    """The "module:function" of the registered runner ``name`` (None: the default); anything
    else is refused, naming the registered ones."""
    import os

    from flagwrap.errors import UserInputError

    if name is None:
        return DEFAULT_RUNNER
    known = dict(RUNNERS)
    for item in filter(None, os.environ.get("FLAGWRAP_SWEEP_RUNNERS", "").split(",")):
        k, _, v = item.partition("=")
        known[k.strip()] = v.strip()
    if isinstance(name, str) and name in known:
        return known[name]
    raise UserInputError(
        f"sweep: runner {name!r} is not a registered case function (registered: "
        f"{', '.join(sorted(known))}); a sweep file names one, it cannot name code to import: "
        "register yours with flagwrap.sweep.case.register_runner or FLAGWRAP_SWEEP_RUNNERS="
        "name=module:function")

#: analysis results copied into a row (analysis.buckling.BucklingAnalysis.summary)
RESULT_KEYS = ("state", "buckled", "waiting_time_turns", "crossing_turns", "max_height",
               "final_height", "winding_turns", "contact_fraction", "torque_peak_reduced",
               "torque_final_reduced", "run_status", "message")


def resolve_runner(target: str | None):
    """Import the case function ``target`` ("module:function" of a registered runner, as a
    case carries it from :func:`runner_target`; None: the default)."""
    mod, _, fn = (target or DEFAULT_RUNNER).partition(":")
    return getattr(importlib.import_module(mod), fn)


def verdict(res: dict) -> tuple[str, str | None]:
    """``(status, error)`` of a case function's result: ``"ok"`` only with a buckling verdict.

    As in :class:`flagwrap.analysis.critical.RunCache`: a run that stopped early (a numerical
    guard tripped) without buckling has no verdict — "stable" would be a guess.
    """
    buckled, run_status = res.get("buckled"), str(res.get("run_status", ""))
    if buckled is None or res.get("state") == "failed":
        return "failed", f"no buckling verdict: {res.get('message', '')}"
    if not buckled and run_status not in ("completed", ""):
        return "failed", f"run {run_status} before a verdict: {res.get('message', '')}"
    return "ok", None


def case_row(case: Case, key: str | None = None) -> dict:
    """The parameter part of a case's row."""
    from flagwrap import __version__

    return {"key": key or case.key, "version": __version__, **case.to_dict()}


def run_case(case: Case, root) -> dict:
    """Run one case, write its run file and row (atomically) under ``root``, return the row.

    Never raises for a failure of the case itself: the row then has ``status = "failed"``,
    ``state = "failed"`` and ``error`` = ``"ExceptionType: message"``.
    """
    store = SweepStore(root)
    key = case.key
    row = case_row(case, key)
    path = store.run_path(key)
    t0 = time.perf_counter()
    try:
        fn = resolve_runner(case.runner)
        res = fn(case.config(), path, case.run.get("stop_after"))
        for k in RESULT_KEYS:
            if k in res:
                row[k] = res[k]
        row["status"], row["error"] = verdict(res)
    except Exception as exc:  # a failed case is a result, not the end of the sweep
        row.update(status="failed", state="failed", buckled=None,
                   error=f"{type(exc).__name__}: {exc}")
    row["wall_time_s"] = time.perf_counter() - t0
    row["finished_at"] = now_iso()
    row["host"] = socket.gethostname()
    row["run_file"] = str(path) if path.is_file() else None
    store.write_row(row)
    return row


def now_iso() -> str:
    """The current time as ISO 8601 in UTC with seconds (rows and tables: readable, sortable)."""
    import datetime

    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")
