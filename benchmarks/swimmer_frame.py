"""The free swimmer in the motor's frame against the lab (body) frame: one turn of steady
swimming at equal accuracy (issue "A wrapping bacterium in minutes", item 1).

Run: ``python benchmarks/swimmer_frame.py [--tol 1e-5] [--ref-tol 1e-8]``

The cell of ``examples/s_putrefaciens.toml`` with its torque-speed motor (``--motor case``,
the default) or a speed motor at its reference 50 Hz (``--motor speed``), on one core (BLAS
limited to one thread):

1. a steady state: 2 turns from rest in the lab frame at tol 1e-7;
2. from it, one more reference turn (20 ms) in each frame at ``--tol`` (the default frame's, 1e-5) and at
   ``--ref-tol`` (the reference), after a 0.01-turn run of each has loaded the kernels.

Prints each run's steps, rejected steps and seconds (also per motor turn), the ratios lab / turning frame, and each
tol run's error against both references (the two frames' tight runs, which must agree with
each other well below the errors they measure): the body's position and the free end's
position at the turn's end [L], and the mean swimming speed over the turn (the body's
displacement over the time) [relative].
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

import numpy as np
from threadpoolctl import threadpool_limits

from flagwrap.io.config import load_config
from flagwrap.params import Motor, Phase
from flagwrap.simulation import Simulation, make_system


MOTOR = "case"


def config(turns: float, frame: str, tol: float):
    sp = load_config("examples/s_putrefaciens.toml")
    motor = (dataclasses.replace(sp.motor, protocol=(Phase("ccw", turns),)) if MOTOR == "case"
             else Motor(frequency=sp.motor.frequency, protocol=(Phase("ccw", turns),)))
    return sp.replace(motor=motor, numerics=dataclasses.replace(sp.numerics, frame=frame,
                                                                 tol=tol))


def in_frame(system, lab_system, y, base):
    """The body-frame swimmer's state ``(y, base)`` in ``system``'s layout and frame."""
    if type(system) is type(lab_system):
        return y.copy(), base
    return system.from_body_frame(y, base)


def one_turn(frame, tol, y0, base0, lab_system, t0):
    cfg = config(3.0, frame, tol)
    sim = Simulation(cfg)
    y, base = in_frame(sim.system, lab_system, y0, base0)
    start = time.perf_counter()
    tr = sim.run(t_end=t0 + 2 * math.pi, y0=y, base=base, t0=t0)
    return tr, time.perf_counter() - start


def measures(tr):
    body = np.asarray(tr.body)
    X0, X1 = body[0][:3], body[-1][:3]
    speed = np.linalg.norm(X1 - X0) / (tr.t[-1] - tr.t[0])
    return X1, np.asarray(tr.x[-1])[-1], speed


def main(argv=None):
    p = argparse.ArgumentParser()
    p.add_argument("--tol", type=float, default=1e-5)
    p.add_argument("--ref-tol", type=float, default=1e-8)
    p.add_argument("--motor", choices=("case", "speed"), default="case",
                   help="the example's torque-speed motor, or a speed motor at its 50 Hz")
    args = p.parse_args(argv)
    global MOTOR
    MOTOR = args.motor
    with threadpool_limits(limits=1):
        for frame in ("lab", "rotating"):  # load the kernels
            Simulation(config(0.01, frame, 1e-3)).run()
        steady = Simulation(config(2.0, "lab", 1e-7))
        tr = steady.run()
        y0, base0, t0 = tr.final_y, tr.final_frames, tr.t[-1]
        lab_system = steady.system
        runs = {}
        for tol in (args.tol, args.ref_tol):
            for frame in ("lab", "rotating"):
                runs[frame, tol] = one_turn(frame, tol, y0, base0, lab_system, t0)
                r, dt = runs[frame, tol]
                turns = abs(r.phi[-1] - r.phi[0]) / (2 * math.pi)
                print(f"{frame:<9s} tol {tol:g}: {r.status} steps {r.n_steps:6d} rejected "
                      f"{r.n_rejected:5d} {dt:8.2f} s over {turns:.2f} motor turns: "
                      f"{r.n_steps / turns:.0f} steps, {dt / turns:.2f} s per motor turn",
                      flush=True)
    (lab, tl), (rot, tr_) = runs["lab", args.tol], runs["rotating", args.tol]
    print(f"lab / turning frame at tol {args.tol:g}: steps {lab.n_steps / rot.n_steps:.1f}x, "
          f"time {tl / tr_:.1f}x")
    refs = {f: measures(runs[f, args.ref_tol][0]) for f in ("lab", "rotating")}
    Xa, ea, va = refs["lab"]
    Xb, eb, vb = refs["rotating"]
    print(f"references (tol {args.ref_tol:g}) apart: body {np.linalg.norm(Xa - Xb):.1e} L, "
          f"free end {np.linalg.norm(ea - eb):.1e} L, speed {abs(va / vb - 1):.1e}")
    print("| run (tol %g) | against | body position [L] | free end [L] | swimming speed |"
          % args.tol)
    print("|---|---|---:|---:|---:|")
    for frame in ("lab", "rotating"):
        X, e, v = measures(runs[frame, args.tol][0])
        for ref in ("lab", "rotating"):
            Xr, er, vr = refs[ref]
            print(f"| {frame} | {ref} reference | {np.linalg.norm(X - Xr):.1e} | "
                  f"{np.linalg.norm(e - er):.1e} | {abs(v / vr - 1):.1e} |")


if __name__ == "__main__":
    main()
