"""Can a coarse space bound the tube's CG iterations? (docs/confinement.md, "Cost"; a study for
the Krylov blob solver, not used by it.)

    python studies/tube_preconditioner.py 0.3 0.2 0.14      # blob spacings of a closed tube

A closed straight tube (radius 1, length 6, blob radius = spacing) and one right-hand side
(a uniform axial flow plus noise): conjugate gradients to rtol 1e-10 with the solver's
block-Jacobi preconditioner (64-blob k-d clusters), then the same with deflation by a coarse
space of one constant force per cluster and direction (Nicolaides; Saad, Yeung, Erhel &
Guyomarc'h, SIAM J. Sci. Comput. 21, 1909 (2000)): ``A Z`` from the RPY blocks summed over each
cluster (one O(n^2) pass), ``E = Z^T A Z`` factorised, every search direction projected.
Prints the iterations and times of both and their solutions' difference.
"""

from __future__ import annotations

import sys
import time

import numpy as np
import scipy.linalg as sla
from scipy.spatial import cKDTree

from flagwrap.body.solver import _cluster_sums as cluster_sums
from flagwrap.confinement.tube import Tube
from flagwrap.hydrodynamics.polydisperse import PolydisperseRPY, rpy_apply_radii


def clusters(b, r, block):
    """The solver's k-d clusters of about ``block`` blobs, each one's cluster index, and the
    Cholesky factors of their own RPY blocks."""
    n = len(b)
    order = np.asarray(cKDTree(b, leafsize=max(1, block // 2)).indices)
    groups = [order[i:i + block] for i in range(0, n, block)]
    cl = np.empty(n, np.int64)
    for k, g in enumerate(groups):
        cl[g] = k
    facs = [sla.cho_factor(PolydisperseRPY(r[g]).matrix(np.ascontiguousarray(b[g])), lower=True)
            for g in groups]
    return groups, cl, facs


def solve(b, r, rhs, block=64, deflate=True, rtol=1e-10, maxiter=2000):
    """``(x, iterations, setup s, solve s)`` of ``M x = rhs`` by (deflated) PCG."""
    n = len(b)
    t0 = time.perf_counter()
    groups, cl, facs = clusters(b, r, block)
    nc = len(groups)

    def A(v):
        out = np.empty((n, 3))
        rpy_apply_radii(b, r, np.ascontiguousarray(v.reshape(-1, 3)), out)
        return out.ravel()

    def B(v):
        v3 = v.reshape(-1, 3)
        out = np.empty_like(v3)
        for g, f in zip(groups, facs):
            out[g] = sla.cho_solve(f, v3[g].ravel()).reshape(-1, 3)
        return out.ravel()

    def Zt(v):  # the sum over each cluster's blobs
        out = np.zeros((nc, 3))
        np.add.at(out, cl, v.reshape(-1, 3))
        return out.ravel()

    def Z(c):
        return c.reshape(-1, 3)[cl].ravel()

    if deflate:
        AZ = np.zeros((3 * n, 3 * nc))
        cluster_sums(b, r, cl, AZ)
        E = np.column_stack([Zt(AZ[:, k]) for k in range(3 * nc)])
        Ef = sla.cho_factor(0.5 * (E + E.T))

        def project(z):
            return z - Z(sla.cho_solve(Ef, AZ.T @ z))

    setup = time.perf_counter() - t0
    t0 = time.perf_counter()
    x = Z(sla.cho_solve(Ef, Zt(rhs))) if deflate else np.zeros(3 * n)
    res = rhs - A(x)
    z = project(B(res)) if deflate else B(res)
    p, rz, it = z.copy(), res @ z, 0
    while np.linalg.norm(res) > rtol * np.linalg.norm(rhs) and it < maxiter:
        w = A(p)
        al = rz / (p @ w)
        x += al * p
        res -= al * w
        z = project(B(res)) if deflate else B(res)
        rz, rz_old = res @ z, rz
        p = z + (rz / rz_old) * p
        it += 1
    return x, it, setup, time.perf_counter() - t0


def main() -> None:
    tube = Tube(1.0, 6.0, closed=True)
    for h in [float(v) for v in sys.argv[1:]] or [0.3, 0.2, 0.14]:
        bl = tube.blob_shell(h, h)
        n = len(bl)
        rad = np.full(n, h)
        rhs = np.tile([0.0, 0.0, 1.0], n) + 0.1 * np.random.default_rng(0).standard_normal(3 * n)
        out, xs = [f"spacing {h} blobs {n}"], []
        for defl in (False, True):
            x, it, st, sv = solve(bl, rad, rhs, deflate=defl)
            xs.append(x)
            out.append(f"{'deflated' if defl else 'block-Jacobi'}: {it} iterations, setup "
                       f"{st:.2f} s, solve {sv:.2f} s")
        out.append(f"difference {np.linalg.norm(xs[0] - xs[1]) / np.linalg.norm(xs[0]):.1e}")
        print(" | ".join(out), flush=True)


if __name__ == "__main__":
    main()
