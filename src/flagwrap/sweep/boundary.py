"""Stability boundary M_c per geometry: by bisection (boundary mode) or from grid rows.

* :func:`run_geometry` (``mode = "boundary"``): :class:`flagwrap.analysis.critical.CriticalSearch`
  for one geometry, bracketing by ``factor`` from ``guess_ratio x 0.06 (R/L)^-3`` and bisecting
  in log M until ``M_hi/M_lo - 1 <= rtol``: ~log2(factor/rtol) + a few runs per geometry
  instead of a dense column of M. Each test run is also an ordinary row.
* :func:`brackets_from_rows`: the same bracket read off any set of rows (grid or boundary):
  ``M_hi`` = smallest buckled M, ``M_lo`` = largest stable M below it; ``M_c = sqrt(M_lo M_hi)``
  with a log half-width ``ln(M_hi/M_lo)/2``. A geometry with only stable (only buckled) rows
  gives a lower (upper) bound.
"""

from __future__ import annotations

import json
import math
import socket
import time
from pathlib import Path

from flagwrap.sweep.case import RESULT_KEYS, case_row, now_iso, resolve_runner, verdict
from flagwrap.sweep.spec import Case
from flagwrap.sweep.store import SweepStore


def geometry_key(case: Case, boundary: dict) -> str:
    import hashlib

    from flagwrap import __version__

    payload = {"geometry": case.geometry(), "run": case.run, "base": case.base,
               "boundary": boundary, "runner": case.runner, "version": __version__}
    text = json.dumps(payload, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def run_geometry(case: Case, root, boundary: dict) -> dict:
    """Boundary mode: bisect for ``M_c`` of ``case``'s geometry and store the result.

    Uses :class:`flagwrap.analysis.critical.CriticalSearch` with a run cache in
    ``root/critical`` (so a killed search resumes from its finished test runs); each test run
    is also written as an ordinary row (the diagram plots them). The first ``M`` tried is
    ``guess_ratio * 0.06 (R/L)^-3``. Never raises; the result has ``status`` ok/failed.
    """
    from flagwrap.analysis.critical import CriticalSearch, RunCache

    store = SweepStore(root)
    gkey = geometry_key(case, boundary)
    fn = resolve_runner(case.runner)
    t0 = time.perf_counter()

    def runner(cfg, path):
        probe = case.with_machin(cfg.machin)
        row = case_row(probe)
        t1 = time.perf_counter()
        res = fn(cfg, path, case.run.get("stop_after"))
        for k in RESULT_KEYS:
            if k in res:
                row[k] = res[k]
        status, error = verdict(res)
        row.update(status=status, error=error, wall_time_s=time.perf_counter() - t1, finished_at=now_iso(),
                   host=socket.gethostname(), run_file=str(path) if Path(path).is_file() else None)
        store.write_row(row)
        return res

    out = {"gkey": gkey, **case.geometry(), "r_over_l_cubed": case.r_over_l ** 3,
           "machin_scaling": case.machin_scaling, "gravity_number": case.gravity_number,
           "boundary": dict(boundary)}
    try:
        search = CriticalSearch(rtol=boundary["rtol"], cw_turns=case.run["cw_turns"],
                                ccw_turns=case.run["ccw_turns"], factor=boundary["factor"],
                                max_runs=boundary["max_runs"],
                                cache=RunCache(store.critical, runner=runner, key_extra=json.dumps(
                                    {"runner": case.runner, "stop_after": case.run.get("stop_after")},
                                    sort_keys=True)))
        search.compute(case.config(), guess=boundary["guess_ratio"] * case.machin_scaling)
        s = search.summary()
        out.update(status="ok", error=None, machin_c=s["machin_c"], bracket=s["bracket"],
                   converged=s["converged"], relative_uncertainty=s["relative_uncertainty"],
                   monotone=s["monotone"], n_runs=len(s["runs"]),
                   runs=[{"machin": r["machin"], "buckled": r["buckled"], "state": r["state"]}
                         for r in s["runs"]])
    except Exception as exc:
        out.update(status="failed", error=f"{type(exc).__name__}: {exc}", machin_c=None,
                   converged=False)
    out["wall_time_s"] = time.perf_counter() - t0
    store.write_boundary(gkey, out)
    return out


def summary_bracket(summary: dict) -> dict:
    """``m_lo``, ``m_hi`` (None where not finite), ``kind`` ("bracket"; "upper": buckled at
    every M tried; "lower": stable at every M tried) and ``machin_c`` (None unless bracketed)
    of one boundary search's stored summary."""
    lo, hi = (summary.get("bracket") or [None, None])[:2]
    lo = lo if lo is not None and math.isfinite(lo) else None
    hi = hi if hi is not None and math.isfinite(hi) else None
    kind = "bracket" if lo is not None and hi is not None else ("upper" if hi is not None else "lower")
    return {"m_lo": lo, "m_hi": hi, "kind": kind,
            "machin_c": summary.get("machin_c") if kind == "bracket" else None}


GEOMETRY_COLUMNS = ("psi_deg", "turns", "r_over_l", "r_over_rcell", "hi", "n_beads",
                    "ccw_turns", "cw_turns", "density_mismatch", "hook_stiffness")
#: values of columns that rows written before the column existed lack
_COLUMN_DEFAULTS = {"density_mismatch": 0.0, "hook_stiffness": None}


def brackets_from_rows(rows) -> list[dict]:
    """Per geometry (rows grouped by :data:`GEOMETRY_COLUMNS`, rounded): the M_c bracket.

    Parameters
    ----------
    rows : iterable of dict
        sweep rows (failed rows are ignored).

    Returns
    -------
    list of dict
        geometry columns, ``r_over_l_cubed``, ``m_lo``, ``m_hi`` (None if missing),
        ``machin_c`` (geometric mean, None unless both), ``sigma_ln`` (``ln(m_hi/m_lo)/2``),
        ``kind`` ("bracket", "lower" = all stable up to m_lo, "upper" = all buckled from m_hi),
        ``monotone`` (no stable row above m_hi), ``n`` (rows).
    """
    groups: dict = {}
    for r in rows:
        if r.get("status") != "ok" or r.get("buckled") is None:
            continue
        v = [r.get(c, _COLUMN_DEFAULTS.get(c)) for c in GEOMETRY_COLUMNS]
        g = tuple(round(float(x), 9) if isinstance(x, float) else x for x in v)
        groups.setdefault(g, []).append(r)
    out = []
    for g, rs in groups.items():
        buckled = sorted(float(r["machin"]) for r in rs if r["buckled"])
        stable = sorted(float(r["machin"]) for r in rs if not r["buckled"])
        hi = buckled[0] if buckled else None
        below = [m for m in stable if hi is None or m < hi]
        lo = below[-1] if below else None
        d = dict(zip(GEOMETRY_COLUMNS, g))
        d["r_over_l_cubed"] = d["r_over_l"] ** 3
        d.update(m_lo=lo, m_hi=hi, n=len(rs), monotone=not (hi is not None and stable and stable[-1] > hi))
        if lo is not None and hi is not None:
            d.update(kind="bracket", machin_c=math.sqrt(lo * hi), sigma_ln=0.5 * math.log(hi / lo))
        else:
            d.update(kind="lower" if hi is None else "upper", machin_c=None, sigma_ln=None)
        out.append(d)
    return sorted(out, key=lambda d: (d["r_over_l"], d["psi_deg"]))
