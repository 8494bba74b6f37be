"""The free S. putrefaciens cell swimming in a tube (or beside a wall) against free space,
and the boundary's two blob solves against each other (docs/confinement.md, "A free cell in
a tube": cost).

Run: ``python benchmarks/tube_swimmer.py [--turns 0.3] [--radius 1.5] [--spacing 0.375]
[--wall X]``

From the extended swimming state (``examples/s_putrefaciens_wrap.toml``'s 4 CCW turns, in
the motor's frame, one core), ``--turns`` more CCW reference turns:

1. in free space;
2. in an open straight tube about the body's axis (radius ``--radius`` um, 10 um long, its
   middle 0.2 um below the motor, blobs ``--spacing`` um apart), the body's blob solve by
   conjugate gradients from a reference factor (``refresh_iterations = 6``, a tube's default);
3. the same with ``refresh_iterations = 0``: the body's blob matrix built and factorised
   exactly at every pose (a wall's default).

With ``--wall X`` a no-slip plane ``x = -X`` um (normal +x, parallel to the cell's axis)
takes the tube's place in 2 and 3.

Prints steps, rejected steps, seconds, the factors built and the CG iterations, the ratios to
free space, and how far the two tube runs' body positions and free ends end apart (the CG
path stops at a residual of 1e-11, so they agree to about the step tolerance's error).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

import numpy as np
from threadpoolctl import threadpool_limits

from flagwrap.cases import case_files
from flagwrap.io.config import load_config
from flagwrap.params import Phase, TubeWall, Wall
from flagwrap.simulation import Simulation


def config(protocol, radius=None, spacing=None, wall=None):
    cfg = load_config(case_files()["s_putrefaciens_wrap"])
    cfg = cfg.replace(motor=dataclasses.replace(cfg.motor, protocol=protocol),
                      numerics=dataclasses.replace(cfg.numerics, frame="rotating"))
    um = 1e-6
    if wall is not None:
        return cfg.replace(walls=(Wall(point=(-wall * um, 0.0, 0.0), normal=(1.0, 0.0, 0.0)),))
    if radius is None:
        return cfg
    return cfg.replace(tubes=(TubeWall(radius=radius * um, length=10 * um,
                                       center=(0.0, 0.0, -0.2 * um), axis=(0.0, 0.0, 1.0),
                                       blob_spacing=spacing * um),))


def run(cfg, y0, base, turns, refresh=None):
    sim = Simulation(cfg)
    s = sim.system
    y = np.array(y0, float)
    y[s.sl_X] = 0.0
    y[s.sl_q] = (1.0, 0.0, 0.0, 0.0)
    if refresh is not None:
        s.boundary.refresh_iterations = refresh
    start = time.perf_counter()
    tr = sim.run(t_end=2 * math.pi * turns, y0=y, base=base, t0=0.0)
    return tr, time.perf_counter() - start, s.boundary


def main(argv=None):
    p = argparse.ArgumentParser()
    p.add_argument("--turns", type=float, default=0.3)
    p.add_argument("--radius", type=float, default=1.5)
    p.add_argument("--spacing", type=float, default=0.375)
    p.add_argument("--wall", type=float, default=None,
                   help="a wall x = -X um instead of the tube")
    args = p.parse_args(argv)
    where = "tube" if args.wall is None else "wall"
    with threadpool_limits(limits=1):
        tr = Simulation(config((Phase("ccw", 4.0),))).run()
        y0, base = tr.final_y, tr.final_frames
        cfg_free = config((Phase("ccw", args.turns),))
        cfg_tube = config((Phase("ccw", args.turns),), args.radius, args.spacing, args.wall)
        run(cfg_tube, y0, base, 0.002)  # load the kernels
        rows = [("free space", *run(cfg_free, y0, base, args.turns)),
                (f"{where}, CG from a reference factor", *run(cfg_tube, y0, base, args.turns, 6)),
                (f"{where}, exact factor per pose", *run(cfg_tube, y0, base, args.turns, 0))]
    if args.wall is None:
        print(f"{args.turns:g} reference turns, tube radius {args.radius:g} um, "
              f"{len(rows[1][3].blobs)} blobs {args.spacing:g} um apart")
    else:
        print(f"{args.turns:g} reference turns, wall x = -{args.wall:g} um")
    f_steps, f_time = rows[0][1].n_steps, rows[0][2]
    print("| run | steps (rejected) | s | factors | CG iterations | steps / free | time / free |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name, r, dt, b in rows:
        fac = "-" if b is None else str(b.refreshed)
        it = "-" if b is None else str(b.iterations)
        print(f"| {name} | {r.n_steps} ({r.n_rejected}) | {dt:.1f} | {fac} | {it} | "
              f"{r.n_steps / f_steps:.2f} | {dt / f_time:.1f} |")
    a, b = rows[1][1], rows[2][1]
    body = np.abs(np.asarray(a.body[-1])[:3] - np.asarray(b.body[-1])[:3]).max()
    tip = np.abs(np.asarray(a.x[-1])[-1] - np.asarray(b.x[-1])[-1]).max()
    print(f"the two {where} runs end apart by: body {body:.1e} L, free end {tip:.1e} L")


if __name__ == "__main__":
    main()
