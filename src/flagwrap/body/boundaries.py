"""A fixed no-slip boundary seen from a moving body: what a free cell needs of a plane wall or
a tube at each pose of its body (:class:`~flagwrap.system.swimmer.SwimmerSystem` steps in the
body's frame, where the boundary is what moves).

A boundary enters the free cell's mobility problem as an addition ``Delta`` to the free-space
RPY blocks among everything that moves (the filament's beads and the body's blobs), and as a
steric wall the beads and blobs meet:

* **A plane** (:class:`WallFromBody`): ``Delta`` is the Rotne-Prager-Blake correction
  (:mod:`flagwrap.hydrodynamics.wall`, Swan & Brady 2007) about the plane in body
  coordinates.
* **A tube** (:class:`TubeFromBody`): a shell of ``T`` no-slip blobs held still in the lab
  (:mod:`flagwrap.confinement.tube`). Eliminating their forces from the joint blob problem
  (Usabiaga et al. 2016, Sec. 3: every blob's velocity is its rigid motion, zero for the
  tube) leaves the Schur complement

      Delta_ij = - M_iT M_TT^-1 M_Tj,

  the tube's screening between any two moving spheres ``i, j``. ``M_TT`` is the tube's own
  RPY matrix: it does not change, so it is factorised (and up to 2500 blobs inverted) once.
  ``M_iT`` is the free RPY block between a moving sphere and the tube's blobs, built at the
  sphere's lab position and turned into body axes: ``Delta`` in body axes is
  ``R^T Delta_lab R`` on each block (rotation covariance of RPY, exact).

Both give, at one pose, a *view* (:meth:`at`) with the same small interface: the body-frame
geometry (for contact), gaps and their gradients, ``Delta`` as a matrix or applied. The view
of a tube keeps ``L^-1 M_Tb`` of the body's blobs (``M_TT = L L^T``), the costliest thing a
pose needs (``27 T^2 n_b`` operations; docs/confinement.md, "A free cell in a tube").
"""

from __future__ import annotations

import dataclasses

import numpy as np
import scipy.linalg as sla

from flagwrap.hydrodynamics.polydisperse import PolydisperseRPY, rpy_cross_radii
from flagwrap.hydrodynamics.wall import (
    PlaneWall,
    wall_correction_apply,
    wall_correction_matrix,
)


def _cross_lab(x, radii, blobs, blob_radii) -> np.ndarray:
    """The free RPY block (3n, 3T) between spheres at ``x`` of ``radii`` and the boundary's
    blobs (lab frame): :func:`~flagwrap.hydrodynamics.polydisperse.rpy_cross_radii` once
    per distinct radius of the spheres (a filament's beads share one; a body's blobs do)."""
    x = np.ascontiguousarray(x, dtype=np.float64)
    radii = np.broadcast_to(np.asarray(radii, float), (len(x),))
    out = np.empty((3 * len(x), 3 * len(blobs)))
    values = np.unique(radii)
    if len(values) == 1:
        rpy_cross_radii(x, float(values[0]), blobs, blob_radii, out)
        return out
    for a in values:
        ids = np.flatnonzero(radii == a)
        part = np.empty((3 * len(ids), 3 * len(blobs)))
        rpy_cross_radii(np.ascontiguousarray(x[ids]), float(a), blobs, blob_radii, part)
        rows = (3 * ids[:, None] + np.arange(3)).ravel()
        out[rows] = part
    return out


class ReferenceFactor:
    """What a boundary seen from a free body shares for the body's blob solve (module
    docstring): the body's blob matrix ``M_bb + Delta_bb(pose)`` changes with every pose, and
    building and factorising it exactly at each costs ``O(n_b^3)`` and ``Delta_bb``'s build.
    Conjugate gradients on it, applied matrix-free (``M_bb`` kept, ``Delta`` applied by the
    view), preconditioned by its Cholesky factor at a *reference* pose, converge in a few
    iterations while the body has moved little against the boundary; when a solve needs more
    than ``refresh_iterations``, the factor is rebuilt exactly at that pose, which becomes the
    reference (and that solve is the factor's own, exact). The reference pose is what the
    solver carries from step to step (:meth:`memory`: a checkpoint keeps it, so a resumed run
    is the uninterrupted one). :class:`ScreenedBlobSolver` is the solve at one pose."""

    #: a solve that needs more conjugate-gradient iterations than this rebuilds the factor
    refresh_iterations = 6
    #: conjugate gradients stop at this residual relative to the right-hand side's
    rtol = 1e-11

    def _reference_setup(self) -> None:
        self.body_blobs = None  # the body's blob array (the object the swimmer passes)
        self._Mbb = None
        self._ref = None  # (pose key (7,), Cholesky factor of M_bb + Delta_bb there)
        self.refreshed = 0  # how many factors were built (benchmarks)
        self.iterations = 0  # conjugate-gradient iterations in all (benchmarks)

    def blob_solver(self, view, blobs, radii, key):
        """The body's blob solve at ``view``'s pose (``key``: the pose's 7 numbers)."""
        if self.body_blobs is None:
            self.body_blobs = blobs
            self._Mbb = PolydisperseRPY(radii).matrix(blobs)
        return ScreenedBlobSolver(self, view, blobs, radii, np.array(key, float))

    def _factor(self, view, blobs, radii, key) -> None:
        M = self._Mbb + view.correction_matrix(blobs, radii, blobs, radii)
        self._ref = (np.array(key, float), sla.cho_factor(M, lower=True, check_finite=False))
        self.refreshed += 1

    def memory(self) -> np.ndarray:
        """The reference pose (7,), or empty before the first factor."""
        return np.zeros(0) if self._ref is None else self._ref[0].copy()

    def restore(self, memory, blobs, radii) -> None:
        """Continue from :meth:`memory`: the factor rebuilt at that pose (the same numbers)."""
        memory = np.asarray(memory, float)
        self._ref = None
        if memory.size:
            from flagwrap.geometry.frames import quaternion_matrix

            self.blob_solver(None, blobs, radii, memory)  # the body's blobs and M_bb
            q = memory[3:] / np.linalg.norm(memory[3:])
            self._factor(self.at(memory[:3], quaternion_matrix(q)), blobs, radii, memory)


class WallView:
    """The plane at one pose, in body coordinates."""

    def __init__(self, wall: PlaneWall, X, R):
        self.geometry = PlaneWall(R.T @ (wall.point - X), R.T @ wall.normal)

    def gap_gradient(self, x) -> tuple[np.ndarray, np.ndarray]:
        """``(gap, grad gap)`` of points ``x`` (n, 3): heights above the plane, its normal."""
        g = self.geometry.heights(x)
        return g, np.broadcast_to(self.geometry.normal, (len(g), 3))

    def correction_matrix(self, xt, at, xs=None, as_=None) -> np.ndarray:
        return wall_correction_matrix(self.geometry, xt, at, xs, as_)

    def correction_apply(self, xt, at, xs, as_, F) -> np.ndarray:
        return wall_correction_apply(self.geometry, xt, at, xs, as_, F)

    def apply(self, xt, at, sources) -> np.ndarray:
        """``sum_s Delta_ts F_s`` at the targets, flat (3n,) or (3n, k) as the ``F_s`` (3m,) or
        (3m, k) of ``sources = [(xs, as_, F_s), ...]``."""
        return _apply_columns(self.correction_apply, xt, at, sources)


class WallFromBody(ReferenceFactor):
    """A plane wall (lab frame, core units) as a free body sees it (module docstring). The
    body's blob matrix ``M_bb + Delta_bb`` is built and factorised exactly at every pose
    (:class:`ReferenceFactor` with ``refresh_iterations = 0``): conjugate gradients from a
    reference factor, the tube's way, cost 6x more here (``python benchmarks/tube_swimmer.py
    --wall 2.1``: 4850 iterations of ~27 ms for 108 steps, where a pose's exact factor takes
    ~50 ms at 470 blobs): the wall's ``Delta`` applied column by column is as dear as
    building it, and the body's spin against the wall keeps the iterations at ~11 a pose."""

    kind = "wall"
    refresh_iterations = 0

    def __init__(self, wall: PlaneWall):
        self.wall = wall
        self.lab_geometry = wall
        self._reference_setup()

    def at(self, X, R) -> WallView:
        return WallView(self.wall, X, R)


def _apply_columns(one, xt, at, sources) -> np.ndarray:
    """``sum_s one(xt, at, xs, as_, F_s)`` for flat ``F_s`` of one or ``k`` columns."""
    out = None
    for xs, as_, F in sources:
        F = np.asarray(F, float)
        cols = F.reshape(len(xs) * 3, -1)
        part = np.column_stack([one(xt, at, xs, as_, cols[:, j].reshape(-1, 3)).ravel()
                                for j in range(cols.shape[1])])
        part = part.reshape(-1) if F.ndim == 1 else part
        out = part if out is None else out + part
    return out


class TubeView:
    """The tube at one pose (module docstring): body-frame geometry and the screening
    ``Delta`` between moving spheres, built from the lab-frame factor of ``M_TT``."""

    def __init__(self, owner: TubeFromBody, X, R):
        self.owner, self.X, self.R = owner, np.asarray(X, float), np.asarray(R, float)
        t = owner.tube
        self.geometry = dataclasses.replace(
            t, center=tuple(R.T @ (np.asarray(t.center) - X)), axis=tuple(R.T @ np.asarray(t.axis)))
        self._kept = None  # (x, L^-1 C^T) of the last source set asked twice (the blobs)
        self._body_cross = None

    def gap_gradient(self, x) -> tuple[np.ndarray, np.ndarray]:
        g, dg, _, _ = self.geometry.gap_gradient(x)
        return g, dg

    def cross(self, x, radii) -> np.ndarray:
        """``M_xT`` (3n, 3T): rows in body axes at body-frame ``x``, columns the tube blobs'
        lab-frame forces; the body's blobs' kept for this pose (asked by every product)."""
        o = self.owner
        if x is o.body_blobs:
            if self._body_cross is None:
                self._body_cross = self._cross(x, radii)
            return self._body_cross
        return self._cross(x, radii)

    def _cross(self, x, radii) -> np.ndarray:
        o, R = self.owner, self.R
        C = _cross_lab(np.asarray(x) @ R.T + self.X, radii, o.blobs, o.blob_radii)
        n = len(x)
        # R^T on each row block: C_body[i] = R^T C_lab[i]
        return np.einsum("ba,nbk->nak", R, C.reshape(n, 3, -1)).reshape(3 * n, -1)

    def _half(self, C) -> np.ndarray:
        """``Z = L^-1 C^T`` with ``M_TT = L L^T``: ``Delta = -Z_t^T Z_s`` (one triangular solve
        and one product: half the operations of ``C_t (M_TT^-1 C_s^T)``)."""
        return sla.solve_triangular(self.owner.solver._L, np.ascontiguousarray(C.T), lower=True,
                                    check_finite=False)

    def _source(self, xs, as_):
        """``Z_s`` of the sources, kept when they are the same array object as last time (a
        body's blobs: asked by every product at this pose)."""
        k = self._kept
        if k is not None and k[0] is xs:
            return k[1]
        Z = self._half(self.cross(xs, as_))
        self._kept = (xs, Z)
        return Z

    def correction_matrix(self, xt, at, xs=None, as_=None) -> np.ndarray:
        """``Delta`` (3n, 3m) between targets and sources (default: the targets)."""
        if xs is None:
            Z = self._half(self.cross(xt, at))
            return -_gram(Z)
        Zs = self._source(xs, as_)
        if xt is xs:
            return -_gram(Zs)
        return -(self._half(self.cross(xt, at)).T @ Zs)

    def correction_apply(self, xt, at, xs, as_, F) -> np.ndarray:
        """``Delta F`` (n, 3) at the targets, no (3n, 3m) matrix: two cross blocks and one
        solve with ``M_TT``."""
        return self.apply(xt, at, [(xs, as_, np.asarray(F, float).ravel())]).reshape(-1, 3)

    def apply(self, xt, at, sources) -> np.ndarray:
        """``sum_s Delta_ts F_s = -M_tT M_TT^-1 sum_s M_Ts F_s`` at the targets, flat (3n,) or
        (3n, k) as the ``F_s`` (3m,) or (3m, k) of ``sources = [(xs, as_, F_s), ...]``: one
        solve with ``M_TT`` for them all."""
        u = None
        for xs, as_, F in sources:
            part = self.cross(xs, as_).T @ np.asarray(F, float)
            u = part if u is None else u + part
        return -(self.cross(xt, at) @ self.owner.solver.solve(u))


def _gram(Z) -> np.ndarray:
    """``Z^T Z`` by BLAS syrk (one triangle, then mirrored)."""
    from scipy.linalg.blas import dsyrk

    G = dsyrk(1.0, np.asfortranarray(Z), trans=1, lower=0)
    return np.triu(G) + np.triu(G, 1).T


class TubeFromBody(ReferenceFactor):
    """A tube (:class:`flagwrap.confinement.tube.Tube`, core units) of no-slip ``blobs`` held
    still in the lab, as a free body sees it (module docstring). ``M_TT`` is factorised here,
    once (:class:`~flagwrap.body.solver.DirectBlobSolver`).

    **The body's blob solve** (:class:`ReferenceFactor`): building ``Delta_bb`` exactly
    costs ``27 T^2 n_b`` operations (0.2-0.6 s for the S. putrefaciens body in a tube of
    600-1100 blobs, several poses a step); a conjugate-gradient product costs two cross
    blocks and one solve with ``M_TT``."""

    kind = "tube"

    def __init__(self, tube, blobs, blob_radii):
        from flagwrap.body.solver import DirectBlobSolver

        self.tube = tube
        self.lab_geometry = tube
        self.blobs = np.ascontiguousarray(blobs, dtype=np.float64)
        self.blob_radii = np.ascontiguousarray(np.broadcast_to(blob_radii, (len(self.blobs),)),
                                               dtype=np.float64)
        self.solver = DirectBlobSolver(self.blobs, self.blob_radii)  # its factor L: Delta
        self._reference_setup()

    def at(self, X, R) -> TubeView:
        return TubeView(self, X, R)

class ScreenedBlobSolver:
    """``(M_bb + Delta_bb)^-1 r`` at one pose of a body beside a boundary (:class:`ReferenceFactor`):
    the reference factor's own solve at the reference pose, preconditioned conjugate
    gradients elsewhere (every column at once)."""

    kind = "screened"

    def __init__(self, owner: ReferenceFactor, view, blobs, radii, key):
        self.owner, self.view, self.blobs, self.radii, self.key = owner, view, blobs, radii, key

    def _matvec(self, V) -> np.ndarray:
        return self.owner._Mbb @ V + self.view.apply(self.blobs, self.radii,
                                                      [(self.blobs, self.radii, V)])

    def solve(self, r) -> np.ndarray:
        o = self.owner
        r = np.asarray(r, float)
        if o._ref is None or (o.refresh_iterations == 0
                              and not np.array_equal(o._ref[0], self.key)):
            o._factor(self.view, self.blobs, self.radii, self.key)
        if np.array_equal(o._ref[0], self.key):
            return sla.cho_solve(o._ref[1], r, check_finite=False)
        R = r.reshape(len(r), -1)
        x, k = _pcg(self._matvec, lambda v: sla.cho_solve(o._ref[1], v, check_finite=False), R,
                    o.rtol, o.refresh_iterations)
        o.iterations += k
        if x is None:  # too many iterations: a new reference factor here, exact
            o._factor(self.view, self.blobs, self.radii, self.key)
            return sla.cho_solve(o._ref[1], r, check_finite=False)
        return x.reshape(r.shape)


def _pcg(matvec, precondition, B, rtol, maxiter):
    """Preconditioned conjugate gradients on the columns of ``B`` at once (symmetric
    positive definite operator): ``(X, iterations)``, ``X`` None if some column has not
    reached ``rtol`` after ``maxiter`` iterations."""
    X = np.zeros_like(B)
    Rr = B.copy()
    bnorm = np.linalg.norm(B, axis=0)
    bnorm[bnorm == 0.0] = 1.0
    Z = precondition(Rr)
    P = Z.copy()
    rz = np.einsum("ij,ij->j", Rr, Z)
    for k in range(maxiter):
        AP = matvec(P)
        alpha = rz / np.einsum("ij,ij->j", P, AP)
        X += alpha * P
        Rr -= alpha * AP
        if np.all(np.linalg.norm(Rr, axis=0) <= rtol * bnorm):
            return X, k + 1
        Z = precondition(Rr)
        rz_new = np.einsum("ij,ij->j", Rr, Z)
        P = Z + (rz_new / rz) * P
        rz = rz_new
    return None, maxiter
