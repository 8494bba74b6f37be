"""Cost of several flagella: a motor turn of a free cell with n flagella against the cell with
one (examples/p_putida_bundle.toml's cell and filament, 81 beads each, 470 blobs), measured in
one run, one thread.

    python benchmarks/bundle.py [--turns 0.3] [--n 1 2 3] [--solver dense krylov]

Prints, per n: unknowns, steps and seconds for the CCW turns, seconds per motor turn, and the
ratio to the first row, and the dense stage solver's buffers (W, A: 2 x 8 ny^2 bytes). The free
swimmer's dense stage solver (``SwimmerW``) costs ny^3 a step (LU) and ny^2 memory; the
matrix-free one (``numerics.linear_solver = "krylov"``, ``SwimmerKrylovW``) one filament's LU
each and the mobility products (docs/bundle.md, "Cost").
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "studies"))


def main(argv=None) -> int:
    from threadpoolctl import threadpool_limits

    from bundle_vs_equivalent import case_config
    from flagwrap.io.config import load_config
    from flagwrap.params import Phase
    from flagwrap.simulation import Simulation

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--turns", type=float, default=0.3)
    p.add_argument("--n", type=int, nargs="+", default=[1, 2, 3])
    p.add_argument("--solver", choices=("dense", "krylov"), nargs="+", default=["dense"],
                   help="numerics.linear_solver: the dense SwimmerW or the matrix-free "
                        "SwimmerKrylovW (each n run with each)")
    args = p.parse_args(argv)
    base = load_config(ROOT / "examples" / "p_putida_bundle.toml")
    base = base.replace(motor=dataclasses.replace(base.motor, protocol=(Phase("ccw", args.turns),)))
    rows = []
    with threadpool_limits(1):
        for solver in args.solver:
            for n in args.n:
                cfg = case_config(base, "single" if n == 1 else f"bundle{n}")
                cfg = cfg.replace(numerics=dataclasses.replace(cfg.numerics,
                                                               linear_solver=solver))
                sim = Simulation(cfg)
                t0 = time.perf_counter()
                tr = sim.run()
                dt = time.perf_counter() - t0
                ny = sim.system.ny
                rows.append((solver, n, ny, tr.n_steps, dt, dt / args.turns,
                             2 * 8 * ny * ny / 2**20))
                print(f"{solver} n = {n}: ny = {ny}, {tr.n_steps} steps ({tr.n_rejected} "
                      f"rejected) in {dt:.1f} s -> {dt / args.turns:.1f} s per motor turn, "
                      f"{tr.n_steps / args.turns:.0f} steps per turn"
                      + (f", dense buffers {rows[-1][6]:.1f} MiB" if solver == "dense" else ""),
                      flush=True)
    ref = rows[0]
    for solver, n, ny, steps, dt, per, mem in rows[1:]:
        print(f"ratio {solver} n = {n} / {ref[0]} n = {ref[1]}: time per turn "
              f"{per / ref[5]:.2f}x, steps {steps / ref[3]:.2f}x, time per step "
              f"{(dt / steps) / (ref[4] / ref[3]):.2f}x, unknowns {ny / ref[2]:.2f}x")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
