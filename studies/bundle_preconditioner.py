"""What the free cell's matrix-free stage solver leaves to its iterations: GCR iterations per
step for variants of its preconditioner (docs/bundle.md, "The stage solve's preconditioner").

    python studies/bundle_preconditioner.py [--n 1 3 8] [--steps 40] [--cell free|held]

examples/p_putida_bundle.toml's free cell with ``n`` flagella, ``numerics.linear_solver =
"krylov"``, ``--steps`` steps from rest (speed motor, CCW), for each variant of
:class:`~flagwrap.system.swimmer.SwimmerKrylovW`'s preconditioner:

* ``filaments``: each filament's free-space ``W`` alone (no motor-angle columns, no body);
* ``mutual``: all filaments' mutual free-space flow in one dense block (what a near field
  built from spatial neighbours could at most add to ``filaments``);
* ``motor``: ``filaments`` with the motor angles' columns (block lower triangular);
* ``body``: ``motor`` with the body's rigid motion (rank 6, Woodbury): flagwrap's.

With ``--cell held`` the same cell held still (``body.motion = "fixed"``) on the rig's
matrix-free path (:class:`~flagwrap.integrators.linear.KrylovW`, banded near field along
each chain), against preconditioners built here:

* ``banded``: flagwrap's (``preconditioner_width`` beads along the chain);
* ``spatial<R>``: the RPY blocks of every pair of free beads closer than ``R`` (core units,
  L = 1) in space, whatever filament they are on (a k-d tree), sparse LU (SuperLU);
* ``allpairs``: every pair's free-space block, dense LU (what any near field tends to).

Prints one JSON line per case: iterations per step (four stages), ms per step (one thread
if run so), steps. The variants are the shipped classes with parts of their preconditioner
switched off or replaced here, not options of flagwrap.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
import time
from pathlib import Path

import numba as nb
import numpy as np
import scipy.linalg as sla

from flagwrap.hydrodynamics._kernels import _pair

sys.path.insert(0, str(Path(__file__).resolve().parent))
VARIANTS = ("filaments", "mutual", "motor", "body")
HELD_VARIANTS = ("banded", "spatial0.02", "spatial0.1", "spatial0.2", "spatial0.4", "allpairs")


def _config(n: int, steps: int, motion: str):
    from bundle_vs_equivalent import case_config

    from flagwrap.io.config import load_config
    from flagwrap.params import Phase

    base = load_config(str(Path(__file__).resolve().parents[1] / "examples"
                           / "p_putida_bundle.toml"))
    base = base.replace(motor=dataclasses.replace(base.motor, protocol=(Phase("ccw", 1.0),)),
                        body=dataclasses.replace(base.body, motion=motion),
                        numerics=dataclasses.replace(base.numerics, linear_solver="krylov",
                                                     max_steps=steps))
    return case_config(base, f"bundle{n}" if n > 1 else "single")


def _timed(cfg):
    from flagwrap.simulation import Simulation, make_system

    sim = Simulation(cfg, system=make_system(cfg))
    t0 = time.perf_counter()
    tr = sim.run()
    return tr, time.perf_counter() - t0


@nb.njit(cache=True)
def _pair_blocks(x, a, pairs, out):
    """``out[k]``: the RPY block (viscosity 1) of the pair ``pairs[k]`` of spheres of radius a
    (the core's pair law, ``flagwrap.hydrodynamics._kernels._pair``)."""
    for k in range(pairs.shape[0]):
        i, j = pairs[k, 0], pairs[k, 1]
        d = x[i] - x[j]
        r = np.sqrt(d @ d)
        f, g = _pair(r, a)
        u = d / r if r > 0.0 else 0.0 * d
        for p in range(3):
            for q in range(3):
                out[k, p, q] = g * u[p] * u[q] + (f if p == q else 0.0)


class SpatialW:
    """Sparse LU of ``I - gamma h Mob_near J``, ``Mob_near`` the RPY blocks of the free beads
    closer than ``reach`` in space with the system's own self blocks and twist drag."""

    def __init__(self, system, y, gamma_h, J, reach: float):
        import scipy.sparse as sp
        import scipy.sparse.linalg as spla
        from scipy.spatial import cKDTree

        x = np.ascontiguousarray(system.free_positions(y), dtype=np.float64)
        nb_, ny, ne = len(x), system.ny, system.ne
        pairs = cKDTree(x).query_pairs(reach, output_type="ndarray").astype(np.int64)
        B = np.empty((len(pairs), 3, 3))
        _pair_blocks(x, system.radius, pairs, B)
        B /= system.machin
        Mb, mt = system.near_field_blocks(y, 0)
        bi = np.concatenate([np.arange(nb_), pairs[:, 0], pairs[:, 1]])
        bj = np.concatenate([np.arange(nb_), pairs[:, 1], pairs[:, 0]])
        bv = np.concatenate([Mb[:, 0], B, B.transpose(0, 2, 1)])
        i3, shape = np.arange(3), (len(bi), 3, 3)
        r = np.broadcast_to(3 * bi[:, None, None] + i3[None, :, None], shape).ravel()
        c = np.broadcast_to(3 * bj[:, None, None] + i3[None, None, :], shape).ravel()
        tw = np.arange(3 * nb_, 3 * nb_ + ne)
        M = sp.csr_matrix((np.concatenate([bv.ravel(), np.broadcast_to(mt, (ne,))]),
                           (np.concatenate([r, tw]), np.concatenate([c, tw]))), shape=(ny, ny))
        self.lu = spla.splu((sp.identity(ny, format="csc") - gamma_h * (M @ J)).tocsc())

    def solve(self, rhs):
        return self.lu.solve(np.asarray(rhs, float))


def _free_space_mobility(system, y, n: int) -> np.ndarray:
    """(n, n): every pair of free beads' free-space RPY block and the twists' drag, the
    system's state order (beads, then twists), zero elsewhere."""
    from flagwrap.hydrodynamics.mobility import RPYMobility

    x = np.ascontiguousarray(system.free_positions(y))
    n3 = 3 * len(x)
    M = np.zeros((n, n))
    M[:n3, :n3] = RPYMobility(system.radius).matrix(x) / system.machin
    tw = np.arange(n3, n3 + system.ne)
    M[tw, tw] = np.broadcast_to(system.twist_mobility, (system.ne,))
    return M


class _Dense:
    def __init__(self, W):
        self.lu = sla.lu_factor(W, check_finite=False)

    def solve(self, r):
        return sla.lu_solve(self.lu, r, check_finite=False)


def _measured(cls, after, cell: str, n: int, variant: str, steps: int) -> dict:
    """``steps`` steps of the ``cell`` ("free" or "held") with ``n`` flagella, every stage
    solver of class ``cls`` handed to ``after(W, system, y, gamma_h)`` once built; its GCR
    iterations per step and the time per step."""
    made = []
    orig = cls.__init__

    def init(self, system, y, base, G0, gamma_h, *a, **k):
        orig(self, system, y, base, G0, gamma_h, *a, **k)
        made.append(self)
        after(self, system, y, gamma_h)

    cls.__init__ = init
    try:
        tr, dt = _timed(_config(n, steps, "free" if cell == "free" else "fixed"))
    finally:
        cls.__init__ = orig
    its = [m.iterations for m in made]
    return {"cell": cell, "n": n, "variant": variant, "steps": tr.n_steps,
            "iterations": sum(its) / len(its), "ms_per_step": 1e3 * dt / tr.n_steps}


def run_held(n: int, variant: str, steps: int) -> dict:
    import flagwrap.integrators.linear as lin

    def after(W, system, y, gamma_h):
        if variant.startswith("spatial"):
            W.P = SpatialW(system, y, gamma_h, W.J, float(variant[7:]))
        elif variant == "allpairs":
            M = _free_space_mobility(system, y, system.ny)
            W.P = _Dense(np.eye(system.ny) - gamma_h * (M @ W.J.toarray()))

    return _measured(lin.KrylovW, after, "held", n, variant, steps)


def run(n: int, variant: str, steps: int) -> dict:
    import flagwrap.system.swimmer as sw

    def after(W, system, y, gamma_h):
        P = W.P
        if variant in ("filaments", "mutual"):
            P.BU = None
            P.blocks = [(I, lu, None) for I, lu, _ in P.blocks]
        if variant == "motor":
            P.BU = None
        if variant == "mutual":
            I = np.concatenate([b[0] for b in P.blocks])
            M = _free_space_mobility(system, y, W.n)
            WI = np.eye(len(I)) - gamma_h * (M[np.ix_(I, I)] @ W.J[I][:, I].toarray())
            P.blocks = [(I, sla.lu_factor(WI, check_finite=False), None)]

    return _measured(sw.SwimmerKrylovW, after, "free", n, variant, steps)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--n", type=int, nargs="+", default=[1, 3, 8])
    p.add_argument("--steps", type=int, default=40)
    p.add_argument("--cell", choices=("free", "held"), default="free")
    p.add_argument("--variants", nargs="+", choices=VARIANTS + HELD_VARIANTS, default=None)
    a = p.parse_args(argv)
    fun = run if a.cell == "free" else run_held
    variants = a.variants or (VARIANTS if a.cell == "free" else HELD_VARIANTS)
    fun(1, variants[-1], 3)  # compile every kernel before timing
    for n in a.n:
        for v in variants:
            print(json.dumps(fun(n, v, a.steps)), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
