"""The stability boundary of a sweep's geometries: M_c (CW) of each helix by linear stability.

A sweep file (grid or boundary mode, :mod:`flagwrap.sweep.spec`) names geometries; each gets
:func:`flagwrap.stability.threshold.find_critical` on its config (the speed is irrelevant
here). The runs are independent and take seconds, so they go to a process pool with one
BLAS thread each (``workers``, default the cores). The result file is JSON, one row per
geometry with the helix, ``M_c``, the crossing, and the fit of ``M_c = c (R/L)^-beta`` over
the rows with a crossing. It is written atomically and read by ``flagwrap figure fig5``.
"""

from __future__ import annotations

import math
import time

DEFAULT_OUT = "out/stability/fig5.json"


def geometry_configs(spec) -> list:
    """``(geometry dict, Config)`` per distinct geometry of a sweep spec."""
    out = []
    seen = set()
    for case in spec.cases:
        g = case.geometry()
        key = tuple(sorted(g.items()))
        if key in seen:
            continue
        seen.add(key)
        out.append((g, case.config()))
    return out


def helix_threshold(item, m_factor: float = 30.0, rtol: float = 1e-3, far: bool = False) -> dict:
    """M_c of one ``(geometry, config)``: the continuation runs to ``m_factor`` x the paper's
    scaling line. ``far``: also the far branch's fold ``M_f``
    (:func:`flagwrap.stability.bifurcation.bifurcation_diagram`, no Hopf cycles). Returns a
    JSON-able row (never raises for a physics failure: the row says what happened)."""
    from threadpoolctl import threadpool_limits

    from flagwrap.stability.threshold import critical_from_config

    g, cfg = item
    extra = {}
    with threadpool_limits(1):
        t0 = time.perf_counter()
        if far:
            from flagwrap.stability.bifurcation import FarStateNotFound, bifurcation_diagram

            try:
                d = bifurcation_diagram(cfg, cycles=())
                extra = {"far_found": True, "far_message": d.message}
            except FarStateNotFound as exc:
                d = exc.diagram
                extra = {"far_found": False, "far_message": str(exc)}
            r = d.hopf
            reduced = cfg.filament.helix_radius / cfg.filament.length  # A/L -> A/R
            tq = d.torques()
            extra.update(
                torque_c_reduced=tq["hopf"] * reduced if "hopf" in tq else None,
                torque_fold_reduced=(tq["fold"] * reduced
                                     if d.fold_found and "fold" in tq else None),
                machin_fold=d.machin_fold if d.fold_found else None,
                         fold_eigenvalues=[v if math.isfinite(v) else None
                                           for v in d.fold_eigenvalues],
                         far_lost_below=(d.far_lost_below if math.isfinite(d.far_lost_below)
                                         else None),
                         far_lowest=min((p.machin for p in d.far), default=None))
        else:
            r = critical_from_config(cfg, "cw", m_max=m_factor * cfg.machin_critical_scaling,
                                     rtol=rtol)
    row = dict(g)
    row.update(extra)
    row.update(machin_c=r.machin_c if r.converged else None,
               bracket=[None if not math.isfinite(v) else v for v in r.bracket],
               crossing=r.crossing or None, converged=r.converged, message=r.message,
               mode_frequency=r.mode_frequency if r.converged else None,
               machin_scaling=cfg.machin_critical_scaling,
               ratio_to_scaling=(r.machin_c / cfg.machin_critical_scaling) if r.converged else None,
               steady_states=len(r.branch), wall_time_s=time.perf_counter() - t0)
    return row


def fit_power_law(rows) -> dict:
    """``ln M_c = ln c - beta ln (R/L)`` over the rows with a crossing, by the diagram's own
    fit (:func:`flagwrap.plotting.diagram.fit_boundary`). The linear thresholds are sharp
    (rtol 1e-3), so every point gets its floor weight and the fit is plain least squares, with
    errors from the scatter. ``rms_ln`` is that scatter; the paper's line is c = 0.06,
    beta = 3."""
    import numpy as np

    from flagwrap.plotting.diagram import fit_boundary

    pts = [{"kind": "bracket", "r_over_l": r["r_over_l"], "machin_c": r["machin_c"],
            "sigma_ln": 0.0} for r in rows if r.get("machin_c")]
    fit = fit_boundary(pts)
    if math.isfinite(fit["exponent"]):
        x = np.log([p["r_over_l"] for p in pts])
        y = np.log([p["machin_c"] for p in pts])
        resid = y - (math.log(fit["prefactor"]) - fit["exponent"] * x)
        fit["rms_ln"] = float(math.sqrt(np.sum(resid**2) / max(1, len(pts) - 2)))
    return fit


def stability_boundary(spec, workers: int | None = None, on_row=None, **kw) -> dict:
    """Every geometry's row (in the spec's order) and the power-law fit."""
    import os
    from concurrent.futures import ProcessPoolExecutor

    items = geometry_configs(spec)
    workers = workers or min(len(items), os.cpu_count() or 1)
    t0 = time.perf_counter()
    rows = []
    if workers <= 1:
        for it in items:
            rows.append(helix_threshold(it, **kw))
            if on_row:
                on_row(rows[-1])
    else:
        import functools

        with ProcessPoolExecutor(workers) as ex:
            for row in ex.map(functools.partial(helix_threshold, **kw), items):
                rows.append(row)
                if on_row:
                    on_row(row)
    return {"sweep": spec.name, "rows": rows, "fit": fit_power_law(rows), "workers": workers,
            "wall_time_s": time.perf_counter() - t0}


def fig5_helices():
    """The geometries of the built-in fig5 sweep (examples/sweeps/fig5.toml)."""
    from flagwrap.sweep.spec import builtin_specs, load_spec

    return geometry_configs(load_spec(builtin_specs()["fig5"]))
