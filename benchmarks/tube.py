"""The cost of a tube (docs/confinement.md, "Cost"): a held cell's motor turn in a tube against
free space, and the blob solvers against the number of tube blobs.

    python benchmarks/tube.py [--turn] [--scale] [--spacing 0.3 0.2 0.14 0.1 0.07 0.05]
                              [--direct-max 4000] [--krylov-max 20000]

``--turn``: one CCW motor turn of the held S. putrefaciens cell (the s_putrefaciens_50hz_held
case) in free space and inside a straight open tube of radius 1.5 um and length 10 um (blob
spacing 0.3 um, 0.2 R_t: Haberman & Sayre within 0.4 %), in one process after a warm-up run
of each: steps, wall time and their ratio.

``--scale``: a closed straight tube of radius 1 and length 6 (core units, viscosity 1) at
each ``--spacing``, its blobs of radius equal to the spacing; per blob count the direct
solver's build time and time per solve (up to ``--direct-max`` blobs) and the Krylov
solver's build time, time per solve and CG iterations to rtol 1e-10 (its two-level
preconditioner; up to ``--krylov-max`` blobs), the right-hand side a uniform flow along the axis
plus noise (a sphere's drag problem seen from the wall). Memory: the direct solver holds one
or two ``(3 n)^2`` matrices, the Krylov one its blocks' factors and ``9 n^2 / 64`` numbers
of its coarse space (``flagwrap.resources``).

Run on one core (``OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 NUMBA_NUM_THREADS=1``) for the
numbers in the docs.
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import numpy as np


def turn() -> None:
    from flagwrap.cases import case_files
    from flagwrap.io.config import load_config
    from flagwrap.params import Phase, TubeWall
    from flagwrap.simulation import Simulation, make_system

    base = load_config(case_files()["s_putrefaciens_50hz_held"])
    base = base.replace(motor=dataclasses.replace(base.motor, protocol=(Phase("ccw", 1.0),)))
    tube = TubeWall(radius=1.5e-6, length=10e-6, center=(0.0, 0.0, -2e-6), blob_spacing=0.3e-6)
    rows = []
    for name, cfg in (("free space", base), ("tube R 1.5 um", base.replace(tubes=(tube,)))):
        warm = cfg.replace(numerics=dataclasses.replace(cfg.numerics, max_steps=5))
        Simulation(warm, system=make_system(warm)).run()  # compile every kernel
        t0 = time.perf_counter()
        s = make_system(cfg)
        build = time.perf_counter() - t0
        tr = Simulation(cfg, system=s).run()
        blobs = len(getattr(s.mobility, "inner", s.mobility).blobs)
        rows.append((name, blobs, tr.n_steps, tr.n_rejected, build, tr.wall_time))
    print(f"{'case':>14} {'blobs':>6} {'steps':>6} {'rejected':>8} {'build s':>8} {'run s':>8}")
    for r in rows:
        print(f"{r[0]:>14} {r[1]:>6} {r[2]:>6} {r[3]:>8} {r[4]:>8.1f} {r[5]:>8.1f}")
    f, t = rows
    print(f"tube / free space: steps {t[2] / f[2]:.2f}x, time {t[5] / f[5]:.2f}x "
          f"(with the build: {(t[4] + t[5]) / (f[4] + f[5]):.2f}x)")


def scale(spacings, direct_max: int, krylov_max: int) -> None:
    from flagwrap.body.solver import DirectBlobSolver, KrylovBlobSolver
    from flagwrap.confinement.tube import BLOB_RADIUS_RATIO, Tube

    tube = Tube(1.0, 6.0, closed=True)
    print(f"{'spacing':>7} {'blobs':>6} {'direct build s':>14} {'direct solve ms':>15} "
          f"{'krylov build s':>14} {'krylov solve s':>14} {'CG iterations':>13}")
    for h in spacings:
        b = tube.blob_shell(h, BLOB_RADIUS_RATIO * h)
        n = len(b)
        r = np.full(n, BLOB_RADIUS_RATIO * h)
        rng = np.random.default_rng(0)
        rhs = np.tile([0.0, 0.0, 1.0], n) + 0.1 * rng.standard_normal(3 * n)
        db = ds = kb = ks = it = float("nan")
        x_d = None
        if n <= direct_max:
            t0 = time.perf_counter()
            D = DirectBlobSolver(b, r)
            db = time.perf_counter() - t0
            t0 = time.perf_counter()
            for _ in range(5):
                x_d = D.solve(rhs)
            ds = (time.perf_counter() - t0) / 5 * 1e3
            del D
        if n <= krylov_max:
            t0 = time.perf_counter()
            K = KrylovBlobSolver(b, r)
            kb = time.perf_counter() - t0
            t0 = time.perf_counter()
            x_k = K.solve(rhs)
            ks = time.perf_counter() - t0
            it = K.iterations[-1]
            if x_d is not None:
                assert np.linalg.norm(x_k - x_d) < 1e-6 * np.linalg.norm(x_d)
        print(f"{h:>7.3g} {n:>6} {db:>14.2f} {ds:>15.1f} {kb:>14.2f} {ks:>14.2f} {it:>13}",
              flush=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--turn", action="store_true")
    ap.add_argument("--scale", action="store_true")
    ap.add_argument("--spacing", type=float, nargs="+", default=[0.3, 0.2, 0.14, 0.1, 0.07, 0.05])
    ap.add_argument("--direct-max", type=int, default=4000)
    ap.add_argument("--krylov-max", type=int, default=20000)
    args = ap.parse_args(argv)
    if not (args.turn or args.scale):
        args.turn = args.scale = True
    if args.turn:
        turn()
    if args.scale:
        scale(args.spacing, args.direct_max, args.krylov_max)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
