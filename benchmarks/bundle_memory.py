"""Memory of several flagella beside a fixed no-slip body on the Krylov path: peak memory
against beads + blobs (issue 28's "memory linear in beads + blobs").

    python benchmarks/bundle_memory.py [--n 1 2 4 8] [--spacing 0.1 0.07 0.05]

examples/p_putida_bundle.toml's filament (81 beads each) as n flagella on the pole cap of
its cell held fixed, ``numerics.linear_solver = "krylov"`` (matrix-free stage solves,
banded preconditioner) and ``body.solver = "krylov"`` (CG on the blobs, block-Jacobi
preconditioner; the beads x blobs products pair by pair). Each case runs a few steps in a
fresh process and reports its peak resident memory above the process's own after the
imports and a warm-up run of the smallest case, so the build of the system is counted
(``ru_maxrss`` less ``VmRSS``), then a least-squares line
``peak = c0 + c1 (beads) + c2 (blobs)`` and its largest relative residual: linear if small.
The free swimmer is not on this path: its stage solver is dense (docs/bundle.md, "Cost").
"""

from __future__ import annotations

import argparse

from _child import EXAMPLE, run

CHILD = r"""
n, spacing = {n}, {spacing}
base = load_config({example!r})
base = base.replace(motor=dataclasses.replace(base.motor, protocol=(Phase("ccw", 0.002),)),
                    body=dataclasses.replace(base.body, motion="fixed", solver="krylov",
                                             blob_spacing=spacing * 1e-6),
                    numerics=dataclasses.replace(base.numerics, linear_solver="krylov"))
cfg = case_config(base, "bundle%d" % n if n > 1 else "single")
warm = case_config(base.replace(body=dataclasses.replace(base.body, blob_spacing=0.1e-6)),
                   "single")
Simulation(warm, system=make_system(warm)).run()  # compile and warm every kernel
before = rss_kb()
s = make_system(cfg)
sim = Simulation(cfg, system=s)
tr = sim.run()
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps(dict(n=n, beads=s.nb, blobs=len(s.mobility.blobs), steps=tr.n_steps,
                      ok=tr.ok, peak_mb=(peak - before) / 1024.0)))
"""


def main(argv=None) -> int:
    import numpy as np

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, nargs="+", default=[1, 2, 4, 8])
    p.add_argument("--spacing", type=float, nargs="+", default=[0.1, 0.06],
                   help="blob spacings [um]")
    args = p.parse_args(argv)
    rows = []
    for sp in args.spacing:
        for n in args.n:
            r = run(CHILD.format(n=n, spacing=sp, example=EXAMPLE))
            rows.append(r)
            print(f"n = {n}  beads {r['beads']:5d}  blobs {r['blobs']:5d}  steps {r['steps']}  "
                  f"peak above start {r['peak_mb']:7.1f} MB", flush=True)
    A = np.array([[1.0, r["beads"], r["blobs"]] for r in rows])
    y = np.array([r["peak_mb"] for r in rows])
    c, *_ = np.linalg.lstsq(A, y, rcond=None)
    res = np.abs(A @ c - y).max() / y.max()
    print(f"fit: peak = {c[0]:.2f} MB + {c[1] * 1e3:.2f} kB/bead + {c[2] * 1e3:.2f} kB/blob; "
          f"largest residual {res:.1%} of the largest peak")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
