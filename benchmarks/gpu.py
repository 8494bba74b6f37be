"""The JAX mobility backend on whatever device jax has, against the numba direct sum.

Run: ``python benchmarks/gpu.py [--sizes 61 250 1000 4000 16000 64000] [--steps 1000 4000 16000]``

Meant for a machine where jax sees a GPU (on a CPU-only machine it measures jax on the CPU,
which ``mobility_backend = "auto"`` never picks). Everything is measured in this one run on
this one machine, with one CPU core (numba and BLAS limited to one thread) beside the device:

* one ``Mob F`` product on benchmarks/scaling.py's chain for each N: numba ``direct``
  float64 (``apply``) and float32 (``apply_single``, GCR's products), jax float64 and float32,
  host-to-device transfers included (that is what a step pays), each checked against the
  float64 direct sum (up to N = 16000; 64000 only timed against it once);
* the crossover N from which jax is faster than the direct sum, per precision: the value
  ``GPU_AUTO_MIN_BEADS`` in flagwrap/hydrodynamics/mobility.py should follow;
* ROS34PW2 steps (tol 1e-5, GCR stage solver) of the real motion with each backend: wall
  time per attempted step and steps per second (same start, same warm-up).
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numba
import numpy as np
from threadpoolctl import threadpool_limits

from scaling import best_of, run_steps, system_for

from flagwrap.hydrodynamics.mobility import JAXMobility, RPYMobility


def describe_device():
    import jax

    devs = jax.devices()
    print(f"jax {jax.__version__} devices: {', '.join(f'{d.platform}:{d.device_kind}' for d in devs)}")
    # what a float32 matrix product gives at jax's default precision on this device (TF32
    # on recent GPUs): the reason the backend asks for full precision
    import jax.numpy as jnp

    rng = np.random.default_rng(1)
    A, B = rng.standard_normal((2, 512, 512)).astype(np.float32)
    ref = A.astype(np.float64) @ B.astype(np.float64)
    for prec in ("default", "highest"):
        got = np.asarray(jnp.matmul(A, B, precision=None if prec == "default" else "highest"))
        print(f"float32 matmul, precision {prec}: rel. err "
              f"{np.linalg.norm(got - ref) / np.linalg.norm(ref):.1e}")
    print(f"numba {numba.__version__}, numpy {np.__version__}, python {platform.python_version()}, "
          f"{os.cpu_count()} CPUs (one used)", flush=True)


def products(sizes):
    rows = {}
    for N in sizes:
        s = system_for(N)
        rng = np.random.default_rng(0)
        y = s.initial_y()
        y[s.sl_x] += 1e-5 * rng.standard_normal(3 * s.nb)
        x = s.forces(y, s.frames0).x[s.nc:]
        F = rng.standard_normal(x.shape)
        direct, jx = RPYMobility(s.radius), JAXMobility(s.radius)
        fns = {"direct f64": direct.apply, "direct f32": direct.apply_single,
               "jax f64": jx.apply, "jax f32": jx.apply_single}
        rep = 5 if N <= 4000 else (2 if N <= 16000 else 1)
        ref = None
        line = [f"N={N:6d}"]
        times = {}
        for name, fn in fns.items():
            out = fn(x, F)  # compile / warm
            if ref is None:
                ref = out
            err = np.linalg.norm(out - ref) / np.linalg.norm(ref)
            times[name] = best_of(lambda: fn(x, F), rep)
            line.append(f"{name} {times[name] * 1e3:9.3f} ms (rel.err {err:.0e})")
        rows[N] = times
        print("  ".join(line), flush=True)
    for prec in ("f64", "f32"):
        faster = [N for N in sizes if rows[N][f"jax {prec}"] < rows[N][f"direct {prec}"]]
        cross = min(faster) if faster else None
        big = max(sizes)
        print(f"jax {prec} faster than direct {prec} from N = {cross} (of {sizes}); "
              f"speed-up at N = {big}: {rows[big][f'direct {prec}'] / rows[big][f'jax {prec}']:.3g}x",
              flush=True)
    return rows


def steps(sizes, nstep, warm):
    for N in sizes:
        line = [f"N={N:6d} step (ROS34PW2, GCR):"]
        for backend in ("direct", "jax"):
            s = system_for(N, mobility_backend=backend)
            wall, acc, turns_h, _ = run_steps(s, "krylov", nstep, warm)
            line.append(f"{backend} {wall * 1e3:8.1f} ms ({1 / wall:6.1f} steps/s, acc {acc:.2f}, "
                        f"{turns_h:.3g} turns/h)")
        print("  ".join(line), flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[61, 250, 1000, 4000, 16000, 64000])
    ap.add_argument("--steps", type=int, nargs="*", default=[1000, 4000, 16000])
    ap.add_argument("--nstep", type=int, default=6)
    ap.add_argument("--warm", type=int, default=4)
    args = ap.parse_args()
    numba.set_num_threads(1)
    describe_device()
    with threadpool_limits(1):
        products(args.sizes)
        steps(args.steps, args.nstep, args.warm)


if __name__ == "__main__":
    main()
