"""The runs behind the issue-4 figures and table, all cached (nothing is simulated twice).

* :func:`critical` -- this model's ``M_c`` of a shipped geometry by the documented search
  (:data:`SEARCHES`; a fully cached search returns at once).
* :func:`fig4_runs` -- the Fig. 4(a) helix at ``omega / omega_c`` = 0.85 and 2.05 (relative to
  THIS model's measured ``omega_c``), with and without HI, full paper protocol (10 CCW + 10 CW).
* :func:`fig6_runs` -- the helix :data:`FIG6_GEOMETRY` at
  ``eps = (omega - omega_c) / omega_c`` in :data:`FIG6_EPS`, 5 CCW turns and
  :func:`~flagwrap.analysis.waiting_time.default_cw_turns` CW turns, stopped 2 turns after
  the onset is detected (:func:`~flagwrap.analysis.critical.simulate_until_buckled`).

Fig. 6 geometry: the paper uses the ``psi = 70 deg, n = 3`` helix (examples/movie7.toml,
R/L = 0.05). In this model that helix has no buckling threshold by the free-end-rise criterion
up to ``M = 7720`` (16x the scaling line): from ``M ~ 3860`` on it deforms already in the CCW
phase (perversions, free end 0.15 L higher) and the CW phase never brings the free end up
(docs/critical.md, runs in out/critical). The waiting-time law is therefore measured on the
``psi = 70 deg, n = 2`` helix of Fig. 4(a), whose threshold is sharp (:data:`FIG6_GEOMETRY`).

The no-HI runs of Fig. 4 use the same ``M`` as the HI runs (the paper compares at equal
``omega``), i.e. ``omega / omega_c`` is relative to the HI threshold.
"""

from __future__ import annotations

import dataclasses
import functools
from pathlib import Path

# geometry -> (built-in case, flagwrap.cases; equal to examples/<name>.toml, search settings);
# docs/critical.md records the results. Built-in, so the figures work from any directory and
# from a wheel install.
SEARCHES = {
    "fig4a": ("fig4a", {"rtol": 0.1, "bracket": (283.0, 600.0)}),
    # guess: the scaling line 0.06 (R/L)^-3 = 480 times the fig4a ratio M_c / scaling = 4.03
    "movie7": ("movie7", {"rtol": 0.1, "guess": 1930.0}),
}
FIG4_RATIOS = (0.85, 2.05)
FIG6_EPS = (0.1, 0.25, 0.5, 1.0, 2.0)
FIG6_GEOMETRY = "fig4a"


def _config(name, root=None):
    """The geometry's config: the built-in case (``root``: a folder whose
    ``examples/<case>.toml`` to read instead, for a modified checkout)."""
    if root is None:
        from flagwrap.cases import get_case

        return get_case(SEARCHES[name][0])
    from flagwrap.io.config import load_config

    return load_config(Path(root) / "examples" / f"{SEARCHES[name][0]}.toml")


def critical(name: str, cache_dir="out/critical", on_run=None, root=None):
    """The documented :class:`~flagwrap.analysis.critical.CriticalSearch` of geometry ``name``."""
    from flagwrap.analysis.critical import CriticalSearch, RunCache

    _, opts = SEARCHES[name]
    opts = dict(opts)
    s = CriticalSearch(rtol=opts.pop("rtol"), cache=RunCache(cache_dir), on_run=on_run)
    return s.compute(_config(name, root), **opts)


def no_hi(cfg):
    """``cfg`` with hydrodynamic interactions off (self mobility only)."""
    return cfg.replace(numerics=dataclasses.replace(cfg.numerics, hydrodynamics=False))


def fig4_runs(machin_c: float, cache_dir="out/paper", ratios=FIG4_RATIOS, on_run=None, root=None):
    """``{(ratio, hydrodynamics): run file path}`` of the Fig. 4 helix (full 10 + 10 protocol)."""
    from flagwrap.analysis.critical import RunCache, probe_config, simulate_and_analyse

    cache = RunCache(cache_dir, runner=functools.partial(simulate_and_analyse, stop_after=None))
    base = _config("fig4a", root)
    out = {}
    for ratio in ratios:
        for hi in (True, False):
            cfg = probe_config(base if hi else no_hi(base), ratio * machin_c, 10.0, 10.0)
            r = cache.run(cfg)
            if on_run is not None:
                on_run((ratio, hi), r)
            out[(ratio, hi)] = Path(cache_dir) / f"{r.key}.nc"
    return out


def fig6_runs(machin_c: float, cache_dir="out/waiting", eps_values=FIG6_EPS, on_run=None, root=None):
    """Rows of :func:`~flagwrap.analysis.waiting_time.waiting_time_sweep` plus ``path``."""
    from flagwrap.analysis.critical import RunCache
    from flagwrap.analysis.waiting_time import waiting_time_sweep

    rows = waiting_time_sweep(_config(FIG6_GEOMETRY, root), machin_c, eps_values,
                              cache=RunCache(cache_dir), on_run=on_run)
    for r in rows:
        r["path"] = str(Path(cache_dir) / f"{r['key']}.nc")
    return rows


def torque_summary(ds) -> dict:
    """Reduced motor torque ``N_m R / A`` of a CCW -> CW run (paper Fig. 4(c) numbers).

    ``ccw`` = median over the last CCW turn; ``cw_peak`` (most negative) and its time after the
    switch ``cw_peak_turns``; ``cw_final`` = median over the last turn; ``cw_first_turn`` =
    median over the first CW turn; ``cw_early_peak`` = most negative value in the first two CW
    turns (the paper's "peak at the first full CW turn") and its time; plus the run's analysis (state, ``t_c / T``).
    """
    import numpy as np

    from flagwrap.analysis.buckling import find_switch
    from flagwrap.observables import cw_torque_peak

    t = ds["turns"].values
    tq = ds["motor_torque_reduced"].values
    i = find_switch(t, ds["omega"].values)
    t_s = t[i - 1]
    ccw = (t > t_s - 1) & (t <= t_s)
    cw = t > t_s
    peak, peak_turns = cw_torque_peak(t, tq, t_s)
    first = cw & (t <= t_s + 1)
    early = cw & (t <= t_s + 2)
    k = int(np.argmin(np.where(early, tq, np.inf)))
    last = t > t[-1] - 1
    at = ds.attrs
    return {"machin": float(at["machin"]), "hydrodynamics": bool(at.get("hydrodynamics", 1)),
            "ccw": float(np.median(tq[ccw])), "cw_peak": peak, "cw_peak_turns": peak_turns,
            "cw_first_turn": float(np.median(tq[first])),
            "cw_early_peak": float(tq[k]), "cw_early_peak_turns": float(t[k] - t_s), "cw_final": float(np.median(tq[last])),
            "state": str(at.get("analysis_state", "")),
            "waiting_time_turns": float(at.get("analysis_waiting_time_turns", float("nan"))),
            "cw_turns_run": float(t[-1] - t_s)}
