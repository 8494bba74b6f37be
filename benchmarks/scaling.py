"""Cost of one mobility product and one full step against the number of beads N.

Run: ``python benchmarks/scaling.py [--max-n 16000]``

For N = 61, 250, 1000, 4000, 16000 (the Fig. 4(a) helix, HI on, one core):

* mobility product ``Mob F``: numba matrix-free O(N^2) product (``rpy_apply``) and, where the
  3N x 3N matrix fits comfortably (N <= 1000), dense assembly + matvec;
* one ROS34PW2 step with each linear solver (dense LU / matrix-free GMRES), N <= 1000;
* peak Python-heap memory of one force + mobility evaluation (tracemalloc), to show O(N).

Prints a table and the measured dense/Krylov crossover.
"""

from __future__ import annotations

import argparse
import time
import tracemalloc

import numpy as np
from threadpoolctl import threadpool_limits

from flagwrap.cases import get_case
from flagwrap.integrators.ros34pw2 import ROS34PW2
from flagwrap.model import RodSystem
from flagwrap.params import Filament


def system_for(N):
    cfg = get_case("fig4a")
    fil = cfg.filament
    fil = Filament(length=fil.length, helix_radius=fil.helix_radius, pitch=fil.pitch,
                   cross_section_radius=fil.cross_section_radius,
                   youngs_modulus=fil.youngs_modulus, n_beads=N)
    return RodSystem(cfg.replace(filament=fil))


def best_of(fn, repeat):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max-n", type=int, default=16000)
    args = ap.parse_args()
    sizes = [n for n in (61, 250, 1000, 4000, 16000) if n <= args.max_n]
    rows = []
    with threadpool_limits(1):
        for N in sizes:
            s = system_for(N)
            y = s.initial_y()
            rng = np.random.default_rng(0)
            y[s.sl_x] += 1e-5 * rng.standard_normal(3 * s.nb)
            info = s.forces(y, s.frames0)
            x = info.x[s.nc:]
            F = rng.standard_normal(x.shape)
            rep = 5 if N <= 1000 else 1
            s.mobility.apply(x, F)  # compile
            t_mf = best_of(lambda: s.mobility.apply(x, F), rep)
            t_dense = np.nan
            if N <= 1000:
                t_dense = best_of(lambda: s.mobility.matrix(x) @ F.ravel(), rep)
            tracemalloc.start()
            inf2 = s.forces(y, s.frames0)
            s.apply_mobility(y, inf2.G)
            peak = tracemalloc.get_traced_memory()[1]
            tracemalloc.stop()
            step = {}
            if N <= 1000:
                for kind in ("dense", "krylov"):
                    integ = ROS34PW2(tol=1e-5, linear_solver=kind)
                    h = 1e-3 * 2 * np.pi
                    integ.step(s, y, info.frames, info, h, 1.0)  # compile / warm
                    step[kind] = best_of(lambda: integ.step(s, y, info.frames, info, h, 1.0),
                                         2 if N <= 250 else 1)
            rows.append((N, t_mf, t_dense, step.get("dense", np.nan), step.get("krylov", np.nan),
                         peak / 1e6))
            print(f"N={N:6d}  Mob F matrix-free {t_mf * 1e3:9.3f} ms  dense {t_dense * 1e3:9.3f} ms  "
                  f"step dense {step.get('dense', np.nan):8.4f} s  step krylov "
                  f"{step.get('krylov', np.nan):8.4f} s  heap {peak / 1e6:8.2f} MB", flush=True)
    cross = [r[0] for r in rows if np.isfinite(r[3]) and np.isfinite(r[4]) and r[4] < r[3]]
    print("crossover (first N where the Krylov step beats dense):", cross[0] if cross else "none measured")
    big = [r for r in rows if r[0] >= 1000]
    if len(big) >= 2:
        (n1, m1), (n2, m2) = (big[0][0], big[0][5]), (big[-1][0], big[-1][5])
        print(f"memory growth {n1} -> {n2} beads: x{m2 / m1:.1f} for x{n2 / n1:.0f} beads (linear)")


if __name__ == "__main__":
    main()
