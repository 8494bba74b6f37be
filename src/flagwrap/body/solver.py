"""Solves with a fixed blob body's RPY matrix ``M_bb`` (``[body] solver``).

Every product of the no-slip body's mobilities (:class:`~flagwrap.body.fixed_mobility.
FixedBodyMobility`, :class:`~flagwrap.system.swimmer.SwimmerSystem`) needs ``M_bb^-1 r``.
The blobs do not move in the body's frame, so ``M_bb`` is the same for a whole run.

* :class:`DirectBlobSolver`: its Cholesky factor, and up to 1500 blobs its inverse, computed
  once: O(n^2) memory (a 4000-blob body is a 12000^2 matrix, 1.15 GB), each solve O(n^2).
* :class:`KrylovBlobSolver`: conjugate gradients (``M_bb`` is symmetric positive definite)
  with the matrix applied on the fly (the RPY sum) and a two-level preconditioner:
  overlapping blocks of about ``block`` blobs (k-d clusters grown by two spacings) and a
  coarse space of one force per cluster. Memory: the blocks' factors, O(n), and the coarse
  block, ``9 n^2 / block`` numbers; each solve ~30 O(n^2) products, however fine the blobs;
  stops at the relative residual ``rtol``.

``make_blob_solver(kind, ...)``: ``"auto"`` is direct up to ``AUTO_DIRECT_MAX`` blobs (the
direct solve's limit), where the memory check of :mod:`flagwrap.resources` has priced it.
Measured (benchmarks/swimmer.py): memory and time per solve against the number of blobs.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import scipy.linalg as sla
from scipy.linalg.blas import dsymv as _symv

from flagwrap.hydrodynamics.polydisperse import PolydisperseRPY, _pair, rpy_apply_radii
from flagwrap.hydrodynamics.wall import wall_correction_apply, wall_correction_matrix

#: most blobs for which "auto" takes the direct solver (a 4000-blob factor is 1.15 GB; above
#: it the memory grows as n^2, and ``body.solver = "direct"`` asks for it up to
#: params.MAX_BLOBS, where the Krylov solver's is O(n)). Below it the factor is
#: the faster for every fixed set of blobs: a held S. putrefaciens body in a tube (1592
#: blobs) factorises in 1.2 s and solves in 20 ms, where block-Jacobi CG takes 115-192
#: iterations and 3-4 s a solve (docs/confinement.md, "Cost")
AUTO_DIRECT_MAX = 4000
KINDS = ("auto", "direct", "krylov")


class DirectBlobSolver:
    """``M_bb`` factorised once (LAPACK potrf); up to ``INVERSE_MAX`` blobs its inverse too.

    With the inverse a solve is one matrix-vector product: one pass over the n^2 numbers where
    the two triangular solves make two slower ones (344 blobs: 0.11 ms against 0.48 ms on one
    core; 1592 blobs of a held body in a tube: 5.3 ms against 20.1 ms, for 2.2 s more to
    build). Above ``INVERSE_MAX`` blobs the inverse's memory outweighs that, and the factor
    alone solves; at 2500 blobs the inverse is 0.45 GB. The factor overwrites the matrix and
    the inverse is mirrored in place: the peak is one ``(3n)^2`` matrix, two with the
    inverse (measured: 1.11 GB at 3875 blobs, whose matrix is 1.03 GB)."""

    kind = "direct"
    INVERSE_MAX = 2500

    def __init__(self, blobs: np.ndarray, radii: np.ndarray, wall=None, invert: bool = True,
                 extra: np.ndarray | None = None):
        from scipy.linalg import lapack

        Mbb = PolydisperseRPY(radii).matrix(blobs)
        if wall is not None:  # beside a plane wall (flagwrap.hydrodynamics.wall)
            Mbb += wall_correction_matrix(wall, blobs, radii)
        if extra is not None:  # any other boundary's Delta (flagwrap.body.boundaries)
            Mbb += extra
        # in place: the C-ordered symmetric matrix's transpose is itself, Fortran-ordered,
        # which LAPACK takes without a copy (one (3n)^2 matrix at the peak, not two)
        L, info = lapack.dpotrf(Mbb.T, lower=1, overwrite_a=1)
        if info != 0:
            raise ValueError(f"the blob matrix is not positive definite (LAPACK info {info})")
        self._L = L  # its upper triangle is never read (lower=True everywhere)
        self._inv = None
        if invert and len(blobs) <= self.INVERSE_MAX:
            inv, info = lapack.dpotri(L, lower=1, overwrite_c=0)
            if info != 0:
                raise ValueError(f"the blob matrix could not be inverted (LAPACK info {info})")
            _mirror_lower(inv)  # potri fills the lower triangle; the rest is Mbb's
            self._inv = inv
            # the same symmetric matrix in Fortran order, which BLAS takes without a copy
            self._inv_f = inv if inv.flags.f_contiguous else inv.T

    def solve(self, r: np.ndarray) -> np.ndarray:
        """``M_bb^-1 r`` (r: (3n,) or (3n, k)). One right-hand side: BLAS symv, which reads one
        triangle of the symmetric inverse (374 blobs: 0.12 ms against gemv's 0.23)."""
        if self._inv is not None:
            if r.ndim == 1:
                return _symv(1.0, self._inv_f, r, lower=1)
            return self._inv @ r
        return sla.cho_solve((self._L, True), r, check_finite=False)

    def screening(self, C: np.ndarray) -> np.ndarray:
        """``C M_bb^-1 C^T`` as ``Y^T Y``, ``Y = L^-1 C^T``: half the operations of
        ``C (M_bb^-1 C^T)`` for many columns."""
        Y = sla.solve_triangular(self._L, C.T, lower=True, check_finite=False)
        return Y.T @ Y


@nb.njit(cache=True)
def _mirror_lower(a):
    """Copy the lower triangle of the square ``a`` onto its upper one, in place (numpy's
    ``triu``/``tril`` would make two more matrices of its size)."""
    n = a.shape[0]
    for j in range(n):
        for i in range(j + 1, n):
            a[j, i] = a[i, j]


@nb.njit(cache=True)
def _cluster_sums(x, radii, cl, out):
    """``out[3 i + a, 3 c + b] += sum_{j in cluster c} M_ij[a, b]``: the RPY blocks of every
    blob ``i`` with each cluster's blobs summed (``A Z`` of the coarse space; one O(n^2)
    pass, viscosity 1; :func:`flagwrap.hydrodynamics.polydisperse._pair`)."""
    n = x.shape[0]
    for i in range(n):
        for j in range(n):
            c = cl[j]
            if i == j:
                s = 1.0 / (6.0 * math.pi * radii[i])
                for a in range(3):
                    out[3 * i + a, 3 * c + a] += s
                continue
            d0 = x[i, 0] - x[j, 0]
            d1 = x[i, 1] - x[j, 1]
            d2 = x[i, 2] - x[j, 2]
            r = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            f, g = _pair(r, radii[i], radii[j])
            g /= r * r
            d = (d0, d1, d2)
            for a in range(3):
                for b in range(3):
                    out[3 * i + a, 3 * c + b] += g * d[a] * d[b] + (f if a == b else 0.0)


class KrylovBlobSolver:
    """Preconditioned conjugate gradients on ``M_bb`` with a two-level preconditioner.

    * **Overlapping blocks** (additive Schwarz): the blobs cut into k-d clusters of about
      ``block`` blobs; each cluster grown by every blob within ``overlap`` times its blobs'
      nearest-neighbour spacing, and that set's own RPY block factorised; the preconditioner
      sums their solves.
    * **A coarse space** (deflation: Nicolaides; Saad, Yeung, Erhel & Guyomarc'h, SIAM J. Sci.
      Comput. 21, 1909 (2000)): one constant force per cluster and direction, ``Z``; ``A Z``
      summed from the RPY blocks in one O(n^2) pass, ``E = Z^T A Z`` factorised; CG starts
      from the coarse solution and every direction is projected off the coarse space.

    Without overlap (block-Jacobi) the preconditioned matrix keeps many small eigenvalues
    (forces that cancel between neighbouring clusters) and CG's iterations grow with the
    blobs; with both levels they stay ~30 from 555 to 17916 blobs of a tube, where block-Jacobi
    took 154-201 from 555 to 2352 (docs/confinement.md, "Cost"; studies/tube_preconditioner.py).
    Memory: the overlapping blocks' factors (~25 kB a blob at 64-blob clusters and two
    spacings of overlap) and ``A Z`` (``9 n^2 / block`` numbers: 450 MB at 20000 blobs)."""

    kind = "krylov"

    def __init__(self, blobs: np.ndarray, radii: np.ndarray, rtol: float = 1e-10,
                 block: int = 64, maxiter: int = 500, wall=None, overlap: float = 2.0,
                 deflate: bool = True):
        from scipy.spatial import cKDTree

        self.wall = wall
        self.blobs = np.ascontiguousarray(blobs, dtype=np.float64)
        self.radii = np.ascontiguousarray(radii, dtype=np.float64)
        self.rtol, self.maxiter = float(rtol), int(maxiter)
        self.iterations = []  # per solve, for the benchmarks
        n = len(self.blobs)
        tree = cKDTree(self.blobs, leafsize=max(1, block // 2))
        order = np.asarray(tree.indices)
        groups = [order[i:i + block] for i in range(0, n, block)]
        self._cl = np.empty(n, dtype=np.int64)
        for k, g in enumerate(groups):
            self._cl[g] = k
        nn = tree.query(self.blobs, k=2)[0][:, 1] if n > 1 else np.zeros(1)
        self._sets, self._factors = [], []
        for g in groups:
            idx = g
            if overlap > 0 and n > 1:
                reach = 1.01 * overlap * float(np.median(nn[g]))
                idx = np.unique(np.concatenate(
                    [np.asarray(lst, dtype=np.int64) for lst in tree.query_ball_point(self.blobs[g], reach)]))
            Mg = PolydisperseRPY(self.radii[idx]).matrix(np.ascontiguousarray(self.blobs[idx]))
            if wall is not None:
                Mg += wall_correction_matrix(wall, self.blobs[idx], self.radii[idx])
            self._sets.append(idx)
            self._factors.append(sla.cho_factor(Mg, lower=True, check_finite=False))
        self._n = 3 * n
        self._nc = len(groups)
        self._AZ = None
        if deflate:
            AZ = np.zeros((3 * n, 3 * self._nc))
            _cluster_sums(self.blobs, self.radii, self._cl, AZ)
            if wall is not None:  # its correction's columns summed per cluster, rows in chunks
                step = max(1, int(2e7 // (9 * n)))
                for i0 in range(0, n, step):
                    W = wall_correction_matrix(wall, self.blobs[i0:i0 + step],
                                               self.radii[i0:i0 + step], self.blobs, self.radii)
                    AZ[3 * i0:3 * (i0 + step)] += np.stack(
                        [self._coarse(W[k]) for k in range(W.shape[0])])
            E = np.column_stack([self._coarse(AZ[:, k]) for k in range(3 * self._nc)])
            self._E = sla.cho_factor(0.5 * (E + E.T), lower=True, check_finite=False)
            self._AZ = AZ

    def _coarse(self, v: np.ndarray) -> np.ndarray:
        """``Z^T v``: each cluster's forces summed, per direction."""
        out = np.zeros((self._nc, 3))
        np.add.at(out, self._cl, v.reshape(-1, 3))
        return out.ravel()

    def _fine(self, c: np.ndarray) -> np.ndarray:
        """``Z c``: each blob takes its cluster's force."""
        return c.reshape(-1, 3)[self._cl].ravel()

    def apply(self, v: np.ndarray) -> np.ndarray:
        """``M_bb v``, the RPY sum (no matrix)."""
        out = np.empty((len(self.blobs), 3))
        v3 = np.ascontiguousarray(v.reshape(-1, 3))
        rpy_apply_radii(self.blobs, self.radii, v3, out)
        if self.wall is not None:
            out += wall_correction_apply(self.wall, self.blobs, self.radii, self.blobs,
                                         self.radii, v3)
        return out.ravel()

    def _precondition(self, r: np.ndarray) -> np.ndarray:
        r3 = r.reshape(-1, 3)
        out = np.zeros_like(r3)
        for idx, f in zip(self._sets, self._factors):
            out[idx] += sla.cho_solve(f, r3[idx].ravel(), check_finite=False).reshape(-1, 3)
        z = out.ravel()
        if self._AZ is not None:  # off the coarse space, A-orthogonally
            z = z - self._fine(sla.cho_solve(self._E, self._AZ.T @ z, check_finite=False))
        return z

    def _solve1(self, r: np.ndarray) -> np.ndarray:
        x = (self._fine(sla.cho_solve(self._E, self._coarse(r), check_finite=False))
             if self._AZ is not None else np.zeros(self._n))
        res = r - self.apply(x) if self._AZ is not None else r.copy()
        z = self._precondition(res)
        p, rz = z.copy(), res @ z
        stop = self.rtol * np.linalg.norm(r)
        for it in range(self.maxiter + 1):
            if np.linalg.norm(res) <= stop:
                self.iterations.append(it)
                return x
            w = self.apply(p)
            alpha = rz / (p @ w)
            x += alpha * p
            res -= alpha * w
            z = self._precondition(res)
            rz, rz_old = res @ z, rz
            p = z + (rz / rz_old) * p
        raise RuntimeError(f"blob solve: CG did not reach rtol {self.rtol:g} in "
                           f"{self.maxiter} iterations")

    def solve(self, r: np.ndarray) -> np.ndarray:
        r = np.asarray(r, float)
        if r.ndim == 1:
            return self._solve1(r)
        return np.column_stack([self._solve1(r[:, k]) for k in range(r.shape[1])])


def screening_matrix(solver, C: np.ndarray) -> np.ndarray:
    """``C M_bb^-1 C^T`` (m, m) for the cross mobility ``C = M_fb`` (m, 3n)."""
    if isinstance(solver, DirectBlobSolver):
        return solver.screening(C)
    S = C @ solver.solve(np.ascontiguousarray(C.T))
    return 0.5 * (S + S.T)


class LaggedScreening:
    """The screening ``M_fb M_bb^-1 M_bf`` for the stage solver's ``W`` only, recomputed when a
    bead has moved by more than ``refresh`` times its distance to the nearest blob since the
    last computation, else the last one.

    A W-method keeps its order for any ``W`` (Rang & Angermann 2005), so ``W`` may lag the
    beads; what it must not do is leave the screening out. The screening holds the beads next
    to the body back, and without it ``W`` damps their stiff modes at the wrong rate: the step
    controller halves the step (one turn of Fig. 4(a) on a held no-slip body: 2020 steps
    against the exact ``W``'s 1083; 0.3 turn of the free S. putrefaciens cell: 534 against
    267). Exact, it costs a triangular solve with every bead as right-hand side, ~60 % of a
    step. It varies with a bead's position on the scale of its distance ``d`` to the surface,
    so its relative change since the last computation is about ``max |dx| / d``: ``refresh``
    bounds that change. Measured (docs/bacterium.md, "The stage solver"): steps and time
    against ``refresh``.

    Only with the direct solver: with conjugate gradients (:class:`KrylovBlobSolver`) one
    screening is a CG solve per bead coordinate (3n of them, each ~100 O(n_blob^2) products:
    a minute at 415 blobs, an hour at 4000), so there it returns ``None`` and ``W`` goes
    without, at twice the steps."""

    def __init__(self, solver, blobs, cross, refresh: float = 0.3):
        from scipy.spatial import cKDTree

        if not refresh >= 0.0:
            raise ValueError(f"LaggedScreening: refresh must be >= 0, got {refresh}")
        self.solver = solver
        self.cross = cross  # x (n, 3) -> M_fb (3n, 3 n_blobs)
        self.refresh = float(refresh)
        self._tree = cKDTree(np.asarray(blobs))
        self._x = None
        self.computed = 0  # how many times it was computed (for the benchmarks)

    def __call__(self, x: np.ndarray) -> np.ndarray | None:
        """The screening for the beads at ``x`` (n, 3), or ``None`` (a Krylov solver). The
        matrix returned is the object's own: read it, never write it."""
        if self.solver.kind != "direct":
            return None
        if self._x is None or x.shape != self._x.shape or np.any(
                np.linalg.norm(x - self._x, axis=1) > self.refresh * self._d):
            self._compute(np.array(x))
        return self._S

    def _compute(self, x):
        self._S = screening_matrix(self.solver, self.cross(x))
        self._x = x
        self._d = self._tree.query(x)[0]
        self.computed += 1

    def memory(self) -> np.ndarray:
        """What it carries from step to step: the bead positions it was last computed at,
        flattened (empty before the first call). A checkpoint keeps it, so that a resumed run
        steps with the same ``W`` as the uninterrupted one."""
        return np.zeros(0) if self._x is None else self._x.ravel().copy()

    def restore(self, memory) -> None:
        """Continue from :meth:`memory` (empty: start afresh); recomputes the screening there,
        the same numbers as when it was first computed."""
        memory = np.asarray(memory, dtype=np.float64)
        if memory.size == 0 or self.solver.kind != "direct":
            self._x = None
        else:
            self._compute(memory.reshape(-1, 3).copy())


def make_blob_solver(kind: str, blobs, radii, wall=None):
    """The solver ``kind`` ("auto", "direct", "krylov") for these blobs (beside ``wall``, a
    :class:`~flagwrap.hydrodynamics.wall.PlaneWall`, if given)."""
    if kind not in KINDS:
        raise ValueError(f"blob solver must be one of {KINDS}, got {kind!r}")
    if kind == "auto":
        kind = "direct" if len(blobs) <= AUTO_DIRECT_MAX else "krylov"
    if kind == "direct":
        return DirectBlobSolver(blobs, radii, wall=wall)
    return KrylovBlobSolver(blobs, radii, wall=wall)
