"""Cost of one mobility product and one full step against the number of beads N.

Run: ``python benchmarks/scaling.py [--max-n 16000] [--threads 2]``

The chain is the Fig. 4(a) helix (R = 30 mm, pitch, a = 1.5 mm, bond b = L/60) made longer at
the same bond length, so N beads are a filament of length (N - 1) b: the "long filament" of
issue 3 (at N = 61 it is exactly the paper's case). Keeping b/a fixed keeps the near field
(overlapping neighbours) the same size per bead, so memory can be linear in N. One core
(BLAS and numba limited to one thread) unless ``--threads``.

For N = 61, 250, 1000, 4000, 16000:

* ``Mob F`` with each mobility backend installed here: ``direct`` (numba, vectorised),
  ``direct x T`` (numba threads, only with ``--threads`` > 1), ``fmm`` (FMM3D, eps 1e-6 and
  1e-10), ``jax`` (on whatever device jax has; CPU here), each checked against ``direct``;
* ROS34PW2 steps of the real motion (from the stress-free helix at the motor speed, step
  size from the controller, after untimed warm-up steps) with each stage solver: ``dense``
  (exact LU, N <= 1000), ``krylov`` (matrix-free GCR to rtol 1e-3 and 0.1 x the step tolerance per unknown, recycling across
  stages, banded near-field preconditioner; the default above 400 unknowns), ``near``
  (near-field W-method, one banded LU, O(N)); and ROS2 with the GCR solver (``ros2 krylov``,
  same tolerance 1e-5: on long chains its step is several times ROS34PW2's at a larger
  error, benchmarks/long_chain.py compares them at equal accuracy): wall time per attempted
  step, accepted fraction and simulated motor turns per wall hour (the throughput that
  matters: the near W-method's cheap steps are short ones);
* peak traced memory (tracemalloc: numpy buffers) of one ``krylov`` step, to show O(N).

Prints a table, the crossover N where FMM beats the direct sum (if any), and the steps per
second of each stepper at N = 1000.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
import tracemalloc

import numpy as np
from threadpoolctl import threadpool_limits

from flagwrap.cases import get_case
from flagwrap.hydrodynamics.mobility import (FMMMobility, JAXMobility, RPYMobility,
                                             backend_missing)
from flagwrap.integrators import make_integrator
from flagwrap.system.rod_system import RodSystem
from flagwrap.params import Filament


STEPPERS = ("dense", "krylov", "near", "ros2 krylov")  # ROS34PW2 with each solver, then ROS2


def system_for(N, **numerics):
    """The Fig. 4(a) helix extended to N beads at the same bond; ``numerics``: fields of
    ``Numerics`` to change (e.g. ``mobility_backend``)."""
    cfg = get_case("fig4a")
    fil = cfg.filament
    b = fil.length / (fil.n_beads - 1)
    fil = Filament(length=b * (N - 1), helix_radius=fil.helix_radius, pitch=fil.pitch,
                   cross_section_radius=fil.cross_section_radius,
                   youngs_modulus=fil.youngs_modulus, n_beads=N)
    if numerics:
        cfg = cfg.replace(numerics=dataclasses.replace(cfg.numerics, **numerics))
    return RodSystem(cfg.replace(filament=fil))


def best_of(fn, repeat):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def run_steps(s, kind, nstep, warm, trace=False, integrator="ros34pw2"):
    """``warm`` untimed steps (compilation, start-up transient), then ``nstep`` timed ones:
    (wall per attempted step, accepted fraction, turns per wall hour, peak traced memory of
    one more step or None)."""
    integ = make_integrator(integrator, 1e-5, kind)
    y = s.initial_y()
    info = s.forces(y, s.frames0)
    h = 1e-3 * 2 * np.pi
    for _ in range(warm):
        r = integ.step(s, y, info.frames, info, h, 1.0)
        if r.accepted:
            y, info = r.y, r.info
        h = r.h_next
    t_sim = 0.0
    nacc = 0
    t0 = time.perf_counter()
    for _ in range(nstep):
        r = integ.step(s, y, info.frames, info, h, 1.0)
        if r.accepted:
            y, info = r.y, r.info
            t_sim += h
            nacc += 1
        h = r.h_next
    wall = time.perf_counter() - t0
    if nacc == 0:
        print(f"  ({kind}: no step of {nstep} accepted, h = {h:.2e})", flush=True)
    peak = None
    if trace:  # one more step, traced (tracemalloc slows numpy, so not during the timing)
        tracemalloc.start()
        integ.step(s, y, info.frames, info, h, 1.0)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    return wall / nstep, nacc / nstep, t_sim / (2 * np.pi) / wall * 3600.0, peak


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max-n", type=int, default=16000)
    ap.add_argument("--threads", type=int, default=1)
    args = ap.parse_args()
    sizes = [n for n in (61, 250, 1000, 4000, 16000) if n <= args.max_n]
    backends = {"direct": lambda a: RPYMobility(a)}
    if args.threads > 1:
        backends[f"direct x{args.threads}"] = lambda a: RPYMobility(a, threads=args.threads)
    if backend_missing("fmm") is None:
        backends["fmm 1e-6"] = lambda a: FMMMobility(a, eps=1e-6)
        backends["fmm 1e-10"] = lambda a: FMMMobility(a, eps=1e-10)
    if backend_missing("jax") is None:
        backends["jax"] = lambda a: JAXMobility(a)
    print("backends:", ", ".join(backends), flush=True)
    prod = {}
    steps = {}
    with threadpool_limits(1):
        for N in sizes:
            s = system_for(N)
            y = s.initial_y()
            rng = np.random.default_rng(0)
            y[s.sl_x] += 1e-5 * rng.standard_normal(3 * s.nb)
            info = s.forces(y, s.frames0)
            x = info.x[s.nc:]
            F = rng.standard_normal(x.shape)
            ref = None
            line = [f"N={N:6d}  Mob F:"]
            for name, make in backends.items():
                mob = make(s.radius)
                out = mob.apply(x, F)  # compile / warm
                if ref is None:
                    ref = out
                err = np.linalg.norm(out - ref) / np.linalg.norm(ref)
                rep = 5 if N <= 1000 else (2 if N <= 4000 else 1)
                t = best_of(lambda: mob.apply(x, F), rep)
                prod[(N, name)] = t
                line.append(f"{name} {t * 1e3:.3f} ms (rel.err {err:.0e})")
            print("  ".join(line), flush=True)
            line = ["          step:"]
            for kind in STEPPERS:
                if kind == "dense" and N > 1000:
                    continue  # O(N^2) memory, O(N^3) time
                if kind == "ros2 krylov" and N > 4000:
                    continue  # the same products as krylov; N = 16000 takes minutes per step
                # the controller needs ~10 steps to shrink the first step (1e-3 turn) to what long
                # chains take at the start, hence the warm-up counts
                nstep, warm = (40, 10) if N <= 1000 else ((10, 10) if N <= 4000 else (4, 10))
                integ, solver = ("ros2", "krylov") if kind == "ros2 krylov" else ("ros34pw2", kind)
                t, acc, tph, peak = run_steps(s, solver, nstep, warm, trace=(kind == "krylov"),
                                              integrator=integ)
                steps[(N, kind)] = (t, peak)
                line.append(f"{kind} {t:.4f} s (acc {acc:.2f}, {tph:.3g} turns/h"
                            + (f", peak {peak / 1e6:.1f} MB)" if peak else ")"))
            print("  ".join(line), flush=True)
    fmm = [n for n in sizes if (n, "fmm 1e-6") in prod and prod[(n, "fmm 1e-6")] < prod[(n, "direct")]]
    if any(k[1].startswith("fmm") for k in prod):
        print("FMM (eps 1e-6) faster than the direct sum from N =", fmm[0] if fmm else
              f"never up to N = {sizes[-1]}")
    if any(k[0] == 1000 for k in steps):
        print("N = 1000 steps/s: " + ", ".join(f"{kind} {1 / steps[(1000, kind)][0]:.2f}"
                                                for kind in STEPPERS
                                                if (1000, kind) in steps))
    mem = {n: p for (n, k), (_, p) in steps.items() if p}
    big = sorted(n for n in mem if n >= 1000)
    if len(big) >= 2:
        n1, n2 = big[0], big[-1]
        print(f"step memory (krylov) {n1} -> {n2} beads: x{mem[n2] / mem[n1]:.1f} "
              f"for x{n2 / n1:.0f} beads")


if __name__ == "__main__":
    main()
