"""Time and memory of a free cell's step against beads + blobs on the matrix-free stage
solver (``numerics.linear_solver = "krylov"``, ``SwimmerKrylovW``) with the direct blob
solver (issue "A wrapping bacterium in minutes", item 3).

    python benchmarks/swimmer_scale.py [--n 1 3 8] [--spacing 0.1 0.06 0.045] [--steps 15]

examples/p_putida_bundle.toml's free cell with ``n`` flagella (81 beads each, speed motor)
and its body's blobs at each spacing [um]. Each case runs in a fresh process (one thread)
after a warm-up run of the smallest case: ``--steps`` steps from rest (``numerics.max_steps``),
timed apart from the build (the blob factorisation, once per run). Prints per case beads,
blobs, filament unknowns, build seconds, ms per step, GCR iterations per step (four stages)
and the peak resident memory above the warmed process's (``ru_maxrss`` less ``VmRSS``).
"""

from __future__ import annotations

import argparse

from _child import EXAMPLE, run

CHILD = r"""
import flagwrap.system.swimmer as sw

made = []
orig = sw.SwimmerKrylovW.__init__
def init(self, *a, **k):
    orig(self, *a, **k)
    made.append(self)
sw.SwimmerKrylovW.__init__ = init

n, spacing, steps = {n}, {spacing}, {steps}
base = load_config({example!r})
base = base.replace(motor=dataclasses.replace(base.motor, protocol=(Phase("ccw", 1.0),)),
                    body=dataclasses.replace(base.body, solver="direct",
                                             blob_spacing=spacing * 1e-6),
                    numerics=dataclasses.replace(base.numerics, linear_solver="krylov",
                                                 max_steps=steps))
cfg = case_config(base, "bundle%d" % n if n > 1 else "single")
warm = case_config(base.replace(body=dataclasses.replace(base.body, blob_spacing=0.1e-6),
                                numerics=dataclasses.replace(base.numerics, max_steps=3)),
                   "single")
Simulation(warm, system=make_system(warm)).run()  # compile and warm every kernel
made.clear()
before = rss_kb()
t0 = time.perf_counter()
s = make_system(cfg)
sim = Simulation(cfg, system=s)
t1 = time.perf_counter()
tr = sim.run()
t2 = time.perf_counter()
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
its = [m.iterations for m in made]
print(json.dumps(dict(n=n, beads=s.nb, blobs=len(s.blobs), ny=s.n_in, build_s=t1 - t0,
                      ms_per_step=1e3 * (t2 - t1) / max(tr.n_steps, 1), steps=tr.n_steps,
                      iterations=sum(its) / max(len(its), 1), peak_mb=(peak - before) / 1024.0)))
"""


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, nargs="+", default=[1, 3, 8])
    p.add_argument("--spacing", type=float, nargs="+", default=[0.1, 0.06, 0.045],
                   help="blob spacings [um]")
    p.add_argument("--steps", type=int, default=15)
    args = p.parse_args(argv)
    print("| flagella | beads | blobs | beads + blobs | filament unknowns | build [s] | "
          "ms per step | GCR iterations per step | peak memory [MB] |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for sp in args.spacing:
        for n in args.n:
            r = run(CHILD.format(n=n, spacing=sp, steps=args.steps, example=EXAMPLE))
            print(f"| {r['n']} | {r['beads']} | {r['blobs']} | {r['beads'] + r['blobs']} | "
                  f"{r['ny']} | {r['build_s']:.1f} | {r['ms_per_step']:.0f} | "
                  f"{r['iterations']:.1f} | {r['peak_mb']:.0f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
