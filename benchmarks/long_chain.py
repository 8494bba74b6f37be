"""Which stepper for long chains? ROS34PW2 against ROS2 at equal accuracy, full HI.

Run: ``python benchmarks/long_chain.py [--n 1000] [--turns 0.01]``

The chain is benchmarks/scaling.py's: the Fig. 4(a) helix lengthened at the same bond (N
beads, a/b = 0.225, M = 283), started from the stress-free helix at the motor speed. Every
run goes through :class:`flagwrap.simulation.Simulation` (the step control users get) over
the same interval, on one core, with the default stage solver (GCR above 400 unknowns):

* reference: ROS34PW2 with tol = 1e-8;
* ROS34PW2 and ROS2 at tol = 1e-4, 1e-5, 1e-6.

Prints steps, rejections, wall time, attempted steps per second and the largest bead
deviation from the reference (in L of the long chain) for each; then, for the accuracy
levels 1e-3 L and 1e-4 L, the cheapest run of each method that reaches it and the ratio of
their wall times, measured in this one run.

Why: on long chains a soft twist mode of slightly negative curvature grows at ~2500/omega
(N = 1000), and ``W`` is singular at ``gamma h = 1/lambda``. ROS34PW2 resolves the mode and
its step stays below that point whatever the tolerance; ROS2 steps past it, damping the mode
instead of following it (docs/numerics.md, "Long chains: what sets the step"). Which is
better depends on the accuracy wanted, hence this comparison.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

from flagwrap.integrators import make_integrator
from flagwrap.simulation import Simulation

sys.path.insert(0, str(Path(__file__).parent))
from scaling import system_for  # noqa: E402  (the same chain)

TWO_PI = 2 * math.pi


def run(s, name, tol, t_end):
    sim = Simulation(s.config, system=s, integrator=make_integrator(name, tol, "auto"))
    sim.save_dt = t_end  # record the start and the end only
    sim.h0 = 1e-4  # the first step the controller shrinks to anyway (1/omega)
    t0 = time.perf_counter()
    traj = sim.run(t_end=t_end)
    wall = time.perf_counter() - t0
    if not traj.ok:
        raise RuntimeError(f"{name} tol={tol:g}: {traj.message}")
    return traj.x[-1], traj.n_steps, traj.n_rejected, wall


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1000, help="beads (default 1000)")
    ap.add_argument("--turns", type=float, default=0.01, help="interval in motor turns")
    args = ap.parse_args()
    s = system_for(args.n)
    t_end = args.turns * TWO_PI
    print(f"long chain N = {args.n} (a/b = {s.radius / s.bond:.3f}), HI on, "
          f"{args.turns:g} turn from rest, one core", flush=True)
    rows = []
    with threadpool_limits(1):
        run(s, "ros34pw2", 1e-5, 1e-4)  # compile (GCR, float32 kernels) outside the timings
        x_ref, n, rej, wall = run(s, "ros34pw2", 1e-8, t_end)
        print(f"reference ros34pw2 tol 1e-8: {n} steps, {rej} rejected, {wall:.1f} s", flush=True)
        for name in ("ros34pw2", "ros2"):
            for tol in (1e-4, 1e-5, 1e-6):
                x, n, rej, wall = run(s, name, tol, t_end)
                err = float(np.max(np.linalg.norm(x - x_ref, axis=1)))
                rows.append((name, tol, n, rej, wall, err))
                print(f"{name:9s} tol {tol:.0e}: {n:5d} steps {rej:4d} rejected {wall:7.2f} s "
                      f"{(n + rej) / wall:6.1f} steps/s  max|dx| {err:.2e} L", flush=True)
    for level in (1e-3, 1e-4):
        best = {}
        for name, tol, n, rej, wall, err in rows:
            if err <= level and wall < best.get(name, (np.inf,))[0]:
                best[name] = (wall, tol)
        if len(best) == 2:
            (w4, t4), (w2, t2) = best["ros34pw2"], best["ros2"]
            print(f"accuracy {level:.0e} L: ros34pw2 {w4:.2f} s (tol {t4:.0e}), ros2 {w2:.2f} s "
                  f"(tol {t2:.0e}); ratio ros34pw2/ros2: {w4 / w2:.2f}")
        else:
            print(f"accuracy {level:.0e} L: reached only by {', '.join(best) or 'neither'}")


if __name__ == "__main__":
    main()
