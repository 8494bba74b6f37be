"""Run a sweep's cases through Dask, write each result as it finishes, resume after a kill.

Schedulers (``scheduler`` argument, ``flagwrap sweep --scheduler``):

* ``None`` / ``"local"``: a ``dask.distributed.LocalCluster`` on this machine, one
  single-threaded worker process per core (``n_workers``, default ``os.cpu_count()``), one
  case per worker at a time.
* ``"tcp://host:port"`` (any address): an existing Dask scheduler, e.g. one started by
  ``dask-jobqueue`` (SLURM/PBS) or ``dask scheduler`` + ``dask worker`` on many machines. The
  workers must see the sweep folder (shared file system) and have flagwrap installed.
* ``"synchronous"``: every case in this process, in order (no Dask; tests, debugging).

Each case is run by a *case function* ``fn(cfg, path, stop_after) -> dict`` (default
:func:`flagwrap.analysis.critical.simulate_and_analyse`: the test run with early stop after
buckling, run file at ``path``, analysed) inside :func:`run_case`, which never raises: an
exception becomes a row with ``status = "failed"`` and ``error`` = its message, and the sweep
goes on. The row is written by the process that ran the case, atomically
(:class:`~flagwrap.sweep.store.SweepStore`). A case whose row exists is skipped
(``retry_failed`` re-runs failed ones).
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

# one case's run and row live in flagwrap.sweep.case, which the boundary search (imported by
# this module) uses too: no import cycle; the names stay importable from here
from flagwrap.sweep.case import (DEFAULT_RUNNER, RESULT_KEYS, case_row,  # noqa: F401
                                 now_iso, resolve_runner, run_case, verdict)
from flagwrap.sweep.spec import SweepSpec
from flagwrap.sweep.store import SweepStore


@dataclass
class SweepReport:
    """What :func:`run_sweep` did."""

    root: Path
    total: int
    skipped: int
    finished: int = 0
    failed: int = 0
    wall_time_s: float = 0.0
    table_path: Path | None = None
    errors: list = field(default_factory=list)
    failed_before: list = field(default_factory=list)  # (key, error) kept from earlier runs


def _ok(row: dict | None) -> bool:
    return row is not None and row.get("status") == "ok"


def open_client(scheduler, n_workers=None):
    """``(client, cluster)`` for ``scheduler`` (None/"local": a new LocalCluster)."""
    from dask.distributed import Client, LocalCluster

    if scheduler in (None, "local"):
        cluster = LocalCluster(n_workers=n_workers or os.cpu_count() or 1, threads_per_worker=1,
                               processes=True, dashboard_address=":0")
        return Client(cluster), cluster
    try:
        return Client(scheduler, timeout=CONNECT_TIMEOUT_S), None
    except (OSError, TimeoutError) as exc:  # CommClosedError is an OSError
        from flagwrap.errors import UserInputError

        raise UserInputError(f"--scheduler {scheduler}: no Dask scheduler answered within "
                             f"{CONNECT_TIMEOUT_S:g} s ({type(exc).__name__}: "
                             f"{' '.join(str(exc).split())[:200]}); start one (`dask scheduler`) or "
                             "use --scheduler local") from None


#: how long to wait for a remote scheduler before giving up with a message
CONNECT_TIMEOUT_S = 10.0


def run_sweep(spec: SweepSpec, root, scheduler=None, n_workers=None, retry_failed=False,
              progress=False) -> SweepReport:
    """Run every unfinished case (grid) or geometry (boundary) of ``spec`` into ``root``.

    Parameters
    ----------
    spec : SweepSpec
    root : path-like
        sweep folder (``out/sweeps/<name>``).
    scheduler : str or None
        None/"local", "synchronous", or a Dask scheduler address (module docstring).
    n_workers : int, optional
        LocalCluster workers (default: all cores).
    retry_failed : bool
        re-run cases whose row says failed (default: keep them).
    progress : bool
        tqdm bar on stderr with finished / failed / remaining and the ETA.
    """
    store = SweepStore(root)
    store.clean()
    t0 = time.perf_counter()
    if spec.mode == "grid":
        items = spec.cases
        keys = [c.key for c in items]
        done = [store.read_row(k) for k in keys]
        fn, args = run_case, ()
    else:
        from flagwrap.sweep.boundary import geometry_key as _geometry_key
        from flagwrap.sweep.boundary import run_geometry

        items = tuple(spec.geometries())
        keys = [_geometry_key(c, spec.boundary) for c in items]
        done = [store.read_boundary(k) for k in keys]
        fn, args = run_geometry, (spec.boundary,)
    def write_manifest():
        row_keys = keys
        if spec.mode == "boundary":  # the rows are the finished searches' test runs
            row_keys = []
            for c, k in zip(items, keys):
                res = store.read_boundary(k) or {}
                row_keys += [c.with_machin(r["machin"]).key for r in res.get("runs") or ()]
        store.write_manifest(row_keys, keys if spec.mode == "boundary" else ())

    todo = [c for c, d in zip(items, done) if d is None or (retry_failed and not _ok(d))]
    client = cluster = None
    if todo and scheduler != "synchronous":
        # connect before anything is written: an unreachable scheduler changes nothing
        client, cluster = open_client(scheduler, n_workers)
    # first: an interrupted sweep of a changed spec must not leave the old spec's rows current
    # (grid: every key is known now; boundary: updated again at the end)
    write_manifest()
    report = SweepReport(root=Path(root), total=len(items), skipped=len(items) - len(todo))
    report.failed_before = [(k, d.get("error")) for k, d in zip(keys, done)
                            if d is not None and not _ok(d) and not retry_failed]

    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(items), initial=report.skipped, unit="case", dynamic_ncols=True,
                   desc=spec.name)

    def finished(res: dict):
        if res.get("status") == "ok":
            report.finished += 1
        else:
            report.failed += 1
            report.errors.append((res.get("key") or res.get("gkey"), res.get("error")))
        if bar is not None:
            bar.update(1)
            bar.set_postfix(finished=report.finished, failed=report.failed,
                            remaining=len(todo) - report.finished - report.failed)

    if scheduler == "synchronous":
        for c in todo:
            finished(fn(c, str(store.root), *args))
    elif todo:
        from dask.distributed import as_completed

        try:
            futs = {client.submit(fn, c, str(store.root), *args, pure=False): c for c in todo}
            for fut in as_completed(list(futs)):
                try:
                    res = fut.result()
                except Exception as exc:  # the worker died (memory, signal): record it here
                    c = futs[fut]
                    res = case_row(c) if spec.mode == "grid" else {"gkey": _geometry_key(c, spec.boundary)}
                    res.update(status="failed", state="failed",
                               error=f"worker lost: {type(exc).__name__}: {exc}")
                    if spec.mode == "grid":
                        store.write_row(res)
                    else:
                        store.write_boundary(res["gkey"], res)
                finished(res)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    if bar is not None:
        bar.close()
    report.wall_time_s = time.perf_counter() - t0
    write_manifest()
    report.table_path = store.export()
    return report


def fmt_float(v, f=".3g"):
    return "-" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, f)
