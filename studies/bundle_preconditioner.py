"""What the free cell's matrix-free stage solver leaves to its iterations: GCR iterations per
step for variants of its preconditioner (docs/bundle.md, "The stage solve's preconditioner").

    python studies/bundle_preconditioner.py [--n 1 3 8] [--steps 40]

examples/p_putida_bundle.toml's free cell with ``n`` flagella, ``numerics.linear_solver =
"krylov"``, ``--steps`` steps from rest (speed motor, CCW), for each variant of
:class:`~flagwrap.system.swimmer.SwimmerKrylovW`'s preconditioner:

* ``filaments``: each filament's free-space ``W`` alone (no motor-angle columns, no body);
* ``mutual``: all filaments' mutual free-space flow in one dense block (what a near field
  built from spatial neighbours could at most add to ``filaments``);
* ``motor``: ``filaments`` with the motor angles' columns (block lower triangular);
* ``body``: ``motor`` with the body's rigid motion (rank 6, Woodbury): flagwrap's.

Prints one JSON line per case: iterations per step (four stages), ms per step (one thread
if run so), steps. The variants are the shipped class with parts of its preconditioner
switched off here, not options of flagwrap.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path

import numpy as np
import scipy.linalg as sla

sys.path.insert(0, str(Path(__file__).resolve().parent))
VARIANTS = ("filaments", "mutual", "motor", "body")


def run(n: int, variant: str, steps: int) -> dict:
    from bundle_vs_equivalent import case_config

    import flagwrap.system.swimmer as sw
    from flagwrap.io.config import load_config
    from flagwrap.params import Phase
    from flagwrap.simulation import Simulation, make_system

    made = []
    orig = sw.SwimmerKrylovW.__init__

    def init(self, system, y, base, G0, gamma_h, *a, **k):
        orig(self, system, y, base, G0, gamma_h, *a, **k)
        made.append(self)
        P = self.P
        if variant in ("filaments", "mutual"):
            P.BU = None
            P.blocks = [(I, lu, None) for I, lu, _ in P.blocks]
        if variant == "motor":
            P.BU = None
        if variant == "mutual":
            x, _, _ = system.unpack(y)
            xf = np.ascontiguousarray(x[system.free_beads])
            n3 = 3 * len(xf)
            I = np.concatenate([b[0] for b in P.blocks])
            M = np.zeros((self.n, self.n))
            M[:n3, :n3] = system.mobility.matrix(xf) / system.machin
            tw = np.arange(n3, n3 + system.ne)
            M[tw, tw] = np.broadcast_to(system.twist_mobility, (system.ne,))
            W = np.eye(len(I)) - gamma_h * (M[np.ix_(I, I)] @ self.J[I][:, I].toarray())
            P.blocks = [(I, sla.lu_factor(W, check_finite=False), None)]

    sw.SwimmerKrylovW.__init__ = init
    try:
        base = load_config(str(Path(__file__).resolve().parents[1] / "examples"
                               / "p_putida_bundle.toml"))
        base = base.replace(motor=dataclasses.replace(base.motor, protocol=(Phase("ccw", 1.0),)),
                            numerics=dataclasses.replace(base.numerics, linear_solver="krylov",
                                                         max_steps=steps))
        cfg = case_config(base, f"bundle{n}" if n > 1 else "single")
        sim = Simulation(cfg, system=make_system(cfg))
        t0 = time.perf_counter()
        tr = sim.run()
        dt = time.perf_counter() - t0
    finally:
        sw.SwimmerKrylovW.__init__ = orig
    its = [m.iterations for m in made]
    return {"n": n, "variant": variant, "steps": tr.n_steps,
            "iterations": sum(its) / len(its), "ms_per_step": 1e3 * dt / tr.n_steps}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, nargs="+", default=[1, 3, 8])
    p.add_argument("--steps", type=int, default=40)
    p.add_argument("--variants", nargs="+", choices=VARIANTS, default=list(VARIANTS))
    a = p.parse_args(argv)
    run(1, "body", 3)  # compile every kernel before timing
    for n in a.n:
        for v in a.variants:
            print(json.dumps(run(n, v, a.steps)), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
