"""The cost of a free-swimming cell against the paper's rig (issue 19).

Run: ``python benchmarks/swimmer.py [--turns T]``

Measured in one process, on one core (BLAS limited to one thread), each case timed over
``T`` motor turns (default 1) after its start (the same CCW phase, tol 1e-5, HI on), after
a 0.01-turn run of every case has compiled and loaded the kernels:

1. the Fig. 4(a) helix on the paper's fixed transparent body (61 beads), the reference;
2. the same helix on a fixed no-slip body (344 blobs, the default spacing R_cell/3);
3. the same helix on a free no-slip body (344 blobs): the swimmer;
4. S. putrefaciens as in examples/s_putrefaciens.toml (101 beads, 470 blobs, hook), but with
   its motor held at the reference speed so that a motor turn is one reference turn.

Prints steps, rejected steps, seconds and ``ratio`` = seconds / the reference's seconds.
The issue's target: one turn of the free swimmer under 10x one turn of Fig. 4(a).

``--accuracy``: for the no-slip cases, the global error of the tol 1e-5 run over ``T`` turns
against a tol 1e-7 run of the same: the free end's position and the body's [L].

``--refresh R [R ...]``: the S. putrefaciens case over ``T`` turns with the stage solver's
lagged screening (:class:`flagwrap.body.solver.LaggedScreening`) recomputed at each relative
move ``R`` (0: every step): steps, seconds and how often it was computed.

``--memory``: the blob solvers instead (:mod:`flagwrap.body.solver`). For the paper's body at
spacings giving ~500 to ~4000 blobs, each solver's peak memory (tracemalloc, which sees
numpy's buffers) over building it and one mobility product for the 61-bead filament
(``FixedBodyMobility.apply``), the seconds for each, and the CG iterations.
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np
from threadpoolctl import threadpool_limits

from flagwrap.cases import get_case
from flagwrap.io.config import load_config
from flagwrap.params import Motor, Phase
from flagwrap.simulation import simulate


def cases(turns: float):
    cfg = get_case("fig4a")
    motor = dataclasses.replace(cfg.motor, protocol=(Phase("ccw", turns),))
    fig4a = cfg.replace(motor=motor)
    fixed = fig4a.replace(body=dataclasses.replace(fig4a.body, surface="no-slip"))
    free = fig4a.replace(body=dataclasses.replace(fig4a.body, surface="no-slip", motion="free"))
    sp = load_config("examples/s_putrefaciens.toml")
    sp = sp.replace(motor=Motor(frequency=sp.motor.frequency, protocol=(Phase("ccw", turns),)))
    return [("fig4a, fixed transparent (reference)", fig4a), ("fig4a, fixed no-slip", fixed),
            ("fig4a, free no-slip", free), ("S. putrefaciens, free no-slip, hook", sp)]


def memory_table(spacings=(0.038, 0.026, 0.018, 0.0127), solvers=("direct", "krylov")):
    import tracemalloc

    from flagwrap.body.multiblob import inset_capped_cylinder_blobs
    from flagwrap.body.fixed_mobility import FixedBodyMobility
    from flagwrap.system.rod_system import RodSystem

    cfg = get_case("fig4a")
    x = RodSystem(cfg).x0[2:]
    a = cfg.filament.bead_radius / cfg.filament.length
    F = np.random.default_rng(0).standard_normal(x.shape)
    print("| blobs | solver | peak memory [MB] | build [s] | one product [s] | CG iterations |")
    print("|---:|---|---:|---:|---:|---:|")
    for sp in spacings:
        blobs = inset_capped_cylinder_blobs(0.125, 0.625, sp, 0.5 * sp)
        for solver in solvers:
            tracemalloc.start()
            t0 = time.perf_counter()
            mob = FixedBodyMobility(a, blobs, 0.5 * sp, solver=solver)
            t1 = time.perf_counter()
            mob.apply(x, F)
            t2 = time.perf_counter()
            peak = tracemalloc.get_traced_memory()[1] / 1e6
            tracemalloc.stop()
            its = getattr(mob._solver, "iterations", None)
            print(f"| {len(blobs)} | {solver} | {peak:.0f} | {t1 - t0:.2f} | {t2 - t1:.3f} | "
                  f"{its[-1] if its else '-'} |", flush=True)
            del mob


def accuracy_table(turns: float):
    print("| case | steps tol 1e-5 / 1e-7 | free end error [L] | body position error [L] |")
    print("|---|---:|---:|---:|")
    for name, cfg in cases(turns)[1:]:
        runs = [simulate(cfg.replace(numerics=dataclasses.replace(cfg.numerics, tol=tol)))
                for tol in (1e-5, 1e-7)]
        end = [np.asarray(r.x[-1])[-1] for r in runs]
        body = [np.asarray(r.body)[-1][:3] if len(r.body or ()) else np.zeros(3) for r in runs]
        print(f"| {name} | {runs[0].n_steps} / {runs[1].n_steps} | "
              f"{np.linalg.norm(end[0] - end[1]):.1e} | {np.linalg.norm(body[0] - body[1]):.1e} |",
              flush=True)


def refresh_table(turns: float, refreshes):
    import flagwrap.body.solver as bs

    original = bs.LaggedScreening.__init__
    name, cfg = cases(turns)[3]
    simulate(cases(0.01)[3][1])
    try:
        for r in refreshes:
            made = []

            def init(self, solver, blobs, cross, refresh=r):
                original(self, solver, blobs, cross, refresh)
                made.append(self)

            bs.LaggedScreening.__init__ = init
            t0 = time.perf_counter()
            tr = simulate(cfg)
            dt = time.perf_counter() - t0
            print(f"{name}, refresh {r:g}: steps {tr.n_steps} rejected {tr.n_rejected} "
                  f"{dt:.2f} s, screening computed {sum(m.computed for m in made)} times",
                  flush=True)
    finally:
        bs.LaggedScreening.__init__ = original


def main(argv=None):
    p = argparse.ArgumentParser()
    p.add_argument("--turns", type=float, default=1.0)
    p.add_argument("--memory", action="store_true", help="the blob solvers' memory table")
    p.add_argument("--accuracy", action="store_true", help="global error against tol 1e-7")
    p.add_argument("--refresh", type=float, nargs="+", help="lagged screening's refresh scan")
    args = p.parse_args(argv)
    if args.refresh:
        with threadpool_limits(limits=1):
            refresh_table(args.turns, args.refresh)
        return
    if args.accuracy:
        with threadpool_limits(limits=1):
            accuracy_table(args.turns)
        return
    if args.memory:
        with threadpool_limits(limits=1):
            memory_table()
        return
    ref = None
    with threadpool_limits(limits=1):
        for _, cfg in cases(0.01):  # compile and load every kernel first
            simulate(cfg)
        for name, cfg in cases(args.turns):
            t0 = time.perf_counter()
            tr = simulate(cfg)
            dt = time.perf_counter() - t0
            ref = ref or dt
            print(f"{name:<40s} {tr.status:<9s} steps {tr.n_steps:6d} rejected {tr.n_rejected:4d} "
                  f"{dt:8.2f} s  ratio {dt / ref:6.2f}", flush=True)


if __name__ == "__main__":
    main()
