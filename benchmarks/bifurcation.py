"""The cost of one helix's bifurcation diagram (``flagwrap stability --far``).

Run: ``python benchmarks/bifurcation.py [--case fig4a] [--cycles 1.02,1.05]``

Measured in one process, on one core (BLAS limited to one thread), after a tiny diagram has
compiled and loaded the kernels (a short whirl branch and run): the whole diagram of the case's helix (the whirl and its
Hopf, a far state from the reversal, the far branch down to its fold and up to 1.5 M_Hopf,
the Hopf cycles of ``--cycles``), with the time at which each stage ended. Prints M_Hopf,
M_f and the seconds; ``ratio`` = the whole diagram's seconds / 60 (the target: under a minute
on one core).
"""

from __future__ import annotations

import argparse
import platform
import time

from threadpoolctl import threadpool_limits


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", default="fig4a")
    ap.add_argument("--cycles", default="1.02,1.05")
    args = ap.parse_args(argv)
    from flagwrap.cases import get_case
    from flagwrap.stability.bifurcation import bifurcation_diagram

    cycles = tuple(float(v) for v in args.cycles.split(",")) if args.cycles != "none" else ()
    with threadpool_limits(1):
        import dataclasses

        from flagwrap.params import Phase
        from flagwrap.simulation import Simulation, make_system
        from flagwrap.stability.threshold import critical_from_config

        # compile and load the kernels: a short whirl branch and a short turning-frame run
        warm = get_case(args.case)
        critical_from_config(warm, "cw", m_max=60.0)
        warm = warm.replace(motor=dataclasses.replace(warm.motor, protocol=(Phase("cw", 0.2),)),
                            numerics=dataclasses.replace(warm.numerics, frame="rotating"))
        Simulation(warm, system=make_system(warm)).run()
        t0 = time.perf_counter()
        stages = []
        d = bifurcation_diagram(get_case(args.case), cycles=cycles,
                                on_progress=lambda line: stages.append(
                                    (time.perf_counter() - t0, line)))
        total = time.perf_counter() - t0
    print(f"{platform.processor() or platform.machine()}, one core, case {args.case}")
    for t, line in stages:
        print(f"  {t:6.1f} s  {line}")
    print(f"M_Hopf = {d.machin_hopf:.2f}, M_f = {d.machin_fold:.2f}; whole diagram {total:.1f} s "
          f"(ratio {total / 60:.2f} of a minute)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
