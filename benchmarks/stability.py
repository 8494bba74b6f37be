"""The turning frame and the stability tool against the time-domain reference (issue 16).

Run: ``python benchmarks/stability.py [--quick] [--skip-critical] [--skip-fig5]``

Measured in one process, on one core (BLAS limited to one thread), except (3):

1. **M_c of the Fig. 4(a) helix**: ``flagwrap critical`` (bisection of time-domain test runs,
   5 CCW + 10 CW turns, lab frame, bracket 283 .. 600 as in docs/critical.md) to rtol 0.012
   (+-0.6 %, the precision quoted in docs/critical.md), against ``flagwrap stability`` to
   rtol 1e-3, which is finer. ``ratio: critical / stability``. The two answer different
   questions (docs/stability.md): the numbers are printed side by side.
2. **The full Fig. 4(a) protocol** (10 CCW + 10 CW, HI on, tol 1e-5) in the turning frame
   against the lab frame, both checked against a lab run at tol 1e-6: free end within 1e-3 L,
   motor torque within 0.5 % (of its largest value) over the whole run.
   ``ratio: lab / rotating`` (wall time).
3. **The Fig. 5 boundary by the stability tool**: M_c (CW) of the 20 helices of
   examples/sweeps/fig5.toml on 2 worker processes; the wall time.

``--quick``: (1) at rtol 0.1 and (2) over 2 + 2 turns (a smoke test of the script).
"""

from __future__ import annotations

import argparse
import dataclasses
import tempfile
import time

import numpy as np
from threadpoolctl import threadpool_limits

from flagwrap.cases import get_case
from flagwrap.params import Phase
from flagwrap.simulation import simulate


def fig4a(turns, tol=1e-5, frame="lab"):
    cfg = get_case("fig4a")
    motor = dataclasses.replace(cfg.motor, protocol=(Phase("ccw", turns), Phase("cw", turns)))
    return cfg.replace(motor=motor, numerics=dataclasses.replace(cfg.numerics, tol=tol, frame=frame))


def bench_critical(rtol):
    import flagwrap

    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as cache:
        c = flagwrap.critical("fig4a", rtol=rtol, cache=cache, bracket=(283.0, 600.0), max_runs=20)
    t_crit = time.perf_counter() - t0
    t0 = time.perf_counter()
    s = flagwrap.stability("fig4a", rtol=1e-3)
    t_stab = time.perf_counter() - t0
    print(f"flagwrap critical (time domain, rtol {rtol:g}): M_c = {c.machin_c:.1f} "
          f"(bracket {c.bracket[0]:.1f} .. {c.bracket[1]:.1f}), {len(c.runs)} runs, {t_crit:.1f} s")
    print(f"flagwrap stability (linear, rtol 1e-3): M_c = {s.machin_c:.1f} "
          f"(bracket {s.bracket[0]:.2f} .. {s.bracket[1]:.2f}, {s.crossing}), "
          f"{len(s.branch)} steady states, {t_stab:.1f} s")
    print(f"ratio: {t_crit / t_stab:.0f}  (critical / stability, wall time)")


def bench_protocol(turns):
    runs = {}
    for name, tol, frame in (("reference", 1e-6, "lab"), ("lab", 1e-5, "lab"),
                             ("rotating", 1e-5, "rotating")):
        t0 = time.perf_counter()
        tr = simulate(fig4a(turns, tol, frame))
        runs[name] = (tr, time.perf_counter() - t0)
        print(f"{name:9s} tol {tol:g} {frame:8s}: {tr.status}, {tr.n_steps} steps "
              f"({tr.n_rejected} rejected), {runs[name][1]:.1f} s", flush=True)
    ref = runs["reference"][0].arrays()
    for name in ("lab", "rotating"):
        a = runs[name][0].arrays()
        tip = float(np.max(np.linalg.norm(a["x"][:, -1] - ref["x"][:, -1], axis=1)))
        tq = float(np.max(np.abs(a["motor_torque"] - ref["motor_torque"]))
                   / np.max(np.abs(ref["motor_torque"])))
        ok = tip <= 1e-3 and tq <= 5e-3
        print(f"{name:9s} vs reference: free end {tip:.2e} L, torque {100 * tq:.2f} % "
              f"({'within' if ok else 'OUTSIDE'} 1e-3 L / 0.5 %)")
    print(f"ratio: {runs['lab'][1] / runs['rotating'][1]:.1f}  (lab / rotating frame, wall time)")


def bench_fig5(workers=2):
    from flagwrap.stability.boundary import stability_boundary
    from flagwrap.sweep.spec import builtin_specs, load_spec

    res = stability_boundary(load_spec(builtin_specs()["fig5"]), workers=workers)
    found = [r for r in res["rows"] if r["converged"]]
    fit = res["fit"]
    print(f"Fig. 5 boundary by the stability tool: {len(found)} of {len(res['rows'])} helices "
          f"with a crossing, {res['wall_time_s']:.1f} s on {workers} processes; fit "
          f"M_c = {fit.get('prefactor') or float('nan'):.3g} "
          f"(R/L)^-{fit.get('exponent') or float('nan'):.2f}")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true")
    p.add_argument("--skip-critical", action="store_true")
    p.add_argument("--skip-fig5", action="store_true")
    a = p.parse_args()
    with threadpool_limits(1):
        if not a.skip_critical:
            bench_critical(0.1 if a.quick else 0.012)
        bench_protocol(2.0 if a.quick else 10.0)
    if not a.skip_fig5:
        bench_fig5()


if __name__ == "__main__":
    main()
