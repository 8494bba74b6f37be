"""The cost of the polymorph state: a polymorphic filament against the same filament with a
fixed shape (``[polymorph] enabled = false``), per motor turn.

Run: ``python benchmarks/polymorph.py [--case ecoli_polymorph] [--turns 3] [--hz 100]``

Measured in one process, on one core (BLAS limited to one thread), after a short run of each
has compiled the kernels: the case's filament turned CW by a speed motor at ``--hz`` for
``--turns`` turns (below its switching torque: the state stays near A, so both runs ask the
same of the rod), with the polymorph state and without. Prints each run's steps (rejected),
seconds and seconds per turn; ``ratio`` = the polymorphic filament's seconds per turn over the
fixed shape's (the target: at most 1.5).
"""

from __future__ import annotations

import argparse
import dataclasses
import platform
import time

from threadpoolctl import threadpool_limits


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", default="ecoli_polymorph")
    ap.add_argument("--turns", type=float, default=3.0)
    ap.add_argument("--hz", type=float, default=100.0)
    args = ap.parse_args(argv)
    from flagwrap.cases import get_case
    from flagwrap.params import Phase
    from flagwrap.simulation import simulate

    base = get_case(args.case)

    def config(turns, on):
        motor = dataclasses.replace(base.motor, kind="speed", frequency=args.hz, machin=None,
                                    stall_torque=None, zero_load_speed=None,
                                    protocol=(Phase("cw", turns),))
        return base.replace(motor=motor,
                            polymorph=dataclasses.replace(base.polymorph, enabled=on))

    rows = {}
    with threadpool_limits(1):
        for on in (False, True):
            simulate(config(0.05, on))  # compile and load
        for on in (False, True):
            t0 = time.perf_counter()
            tr = simulate(config(args.turns, on))
            rows[on] = (tr.status, tr.n_steps, tr.n_rejected, time.perf_counter() - t0)
    print(f"{platform.processor() or platform.machine()}, one core, case {args.case}, "
          f"{args.turns:g} CW turns at {args.hz:g} Hz")
    for on, name in ((False, "fixed shape"), (True, "polymorphic")):
        st, n, rej, sec = rows[on]
        print(f"  {name:12s} {st}: {n} steps ({rej} rejected), {sec:.2f} s, "
              f"{sec / args.turns:.3f} s per turn")
    ratio = (rows[True][3] / args.turns) / (rows[False][3] / args.turns)
    print(f"ratio (polymorphic / fixed, seconds per turn) = {ratio:.2f} (target <= 1.5); "
          f"steps ratio = {rows[True][1] / rows[False][1]:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
