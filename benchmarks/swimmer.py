"""The cost of a free-swimming cell against the paper's rig (issue 19).

Run: ``python benchmarks/swimmer.py [--turns T]``

Measured in one process, on one core (BLAS limited to one thread), each case timed over
``T`` motor turns (default 1) after its start (the same CCW phase, tol 1e-5, HI on):

1. the Fig. 4(a) helix on the paper's fixed transparent body (61 beads), the reference;
2. the same helix on a fixed no-slip body (344 blobs, the default spacing R_cell/3);
3. the same helix on a free no-slip body (344 blobs): the swimmer;
4. S. putrefaciens as in examples/s_putrefaciens.toml (101 beads, 470 blobs, hook), but with
   its motor held at the reference speed so that a motor turn is one reference turn.

Prints steps, rejected steps, seconds and ``ratio`` = seconds / the reference's seconds.
The issue's target: one turn of the free swimmer under 10x one turn of Fig. 4(a).
"""

from __future__ import annotations

import argparse
import dataclasses
import time

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


def main(argv=None):
    p = argparse.ArgumentParser()
    p.add_argument("--turns", type=float, default=1.0)
    args = p.parse_args(argv)
    ref = None
    with threadpool_limits(limits=1):
        for name, cfg in cases(args.turns):
            t0 = time.perf_counter()
            tr = simulate(cfg)
            dt = time.perf_counter() - t0
            ref = ref or dt
            print(f"{name:<40s} {tr.status:<9s} steps {tr.n_steps:6d} rejected {tr.n_rejected:4d} "
                  f"{dt:8.2f} s  ratio {dt / ref:6.2f}", flush=True)


if __name__ == "__main__":
    main()
