"""The beads' mobility beside a fixed no-slip body: the free-space RPY mobility less the
screening of the body's blobs (rigid multiblob; :mod:`flagwrap.body.multiblob`,
:mod:`flagwrap.body.solver`). It lives with the body, which it needs, so that the RPY
kernels (:mod:`flagwrap.hydrodynamics.polydisperse`) import nothing of the body.
"""

from __future__ import annotations

import math

import numpy as np

from flagwrap.body.solver import (DirectBlobSolver, LaggedScreening, make_blob_solver,
                                  screening_matrix)
from flagwrap.hydrodynamics.polydisperse import rpy_cross_apply, rpy_cross_block
from flagwrap.hydrodynamics.wall import wall_correction_apply, wall_correction_matrix


class FixedBodyMobility:
    """The beads' mobility beside a fixed body with a no-slip surface (rigid multiblob,
    :mod:`flagwrap.body.multiblob`).

    The body's blobs carry forces ``lambda`` that hold its surface still. A bead force ``F``
    moves the blobs at ``M_bf F``, so ``M_bb lambda = -M_bf F``, and the beads move at
    ``(M_ff - M_fb M_bb^-1 M_bf) F``. That Schur complement is the mobility here. ``M_bb`` is
    factorised once, since the body does not move (``solver = "direct"``), or solved by
    conjugate gradients in O(n) memory (``"krylov"``; :mod:`flagwrap.body.solver`). It is
    symmetric and positive definite, and
    smaller than ``M_ff``: the surface screens the flow. Viscosity 1; the bead radius is one
    number, the blobs' radii per blob. It has ``matrix`` and ``apply`` of the mobility
    interface. ``apply_single`` is ``apply``, and ``near_field_blocks`` (for the banded
    preconditioner of the Krylov stage solver) are the free beads': a preconditioner may be
    approximate. Not symmetric about the motor axis (``axisymmetric = False``): the blob shell
    is not, so the turning frame refuses it.
    """

    long_range = True
    backend = "direct+fixed-body"
    axisymmetric = False

    def __init__(self, radius: float, blobs, blob_radii, solver: str = "direct", wall=None):
        from flagwrap.hydrodynamics.mobility import RPYMobility
        from flagwrap.hydrodynamics.wall import WallMobility

        self.wall = wall
        self.radius = float(radius)
        self.self_mobility = 1.0 / (6.0 * math.pi * self.radius)
        self.blobs = np.ascontiguousarray(blobs, dtype=np.float64)
        self.blob_radii = np.ascontiguousarray(np.broadcast_to(blob_radii, (len(self.blobs),)),
                                               dtype=np.float64)
        self._free = RPYMobility(self.radius)
        if wall is not None:  # every block beside the plane (flagwrap.hydrodynamics.wall)
            self._free = WallMobility(self._free, wall)
            self.backend = "direct+fixed-body+wall"
        self._solver = make_blob_solver(solver, self.blobs, self.blob_radii, wall)
        #: products with the beads x blobs block computed pair by pair (the Krylov blob
        #: solver's O(n) memory), not from a stored block (the direct solver's, faster)
        self.matrix_free = not isinstance(self._solver, DirectBlobSolver)
        self._lagged = LaggedScreening(self._solver, self.blobs, self._cross)

    def _cross(self, x):
        C = rpy_cross_block(x, self.radius, self.blobs, self.blob_radii)
        if self.wall is not None:
            C += wall_correction_matrix(self.wall, x, self.radius, self.blobs, self.blob_radii)
        return C

    def screening(self, x) -> np.ndarray:
        """``M_fb M_bb^-1 M_bf`` (3n, 3n): what the body takes off the free mobility."""
        return screening_matrix(self._solver, self._cross(x))

    def matrix(self, x, out=None):
        M = self._free.matrix(x, out=out)
        M -= self.screening(x)
        return M

    def stage_matrix(self, x, out=None):
        """The matrix for the stage solver's ``W`` only (a W-method keeps its order for any
        ``W``): ``M_ff`` less the screening as last computed, recomputed when the beads have
        moved (:class:`~flagwrap.body.solver.LaggedScreening`; with the Krylov solver ``M_ff``
        alone)."""
        M = self._free.matrix(x, out=out)
        S = self._lagged(np.ascontiguousarray(x, dtype=np.float64))
        if S is not None:
            M -= S
        return M

    def solver_memory(self) -> np.ndarray:
        """What :meth:`stage_matrix` carries from step to step
        (:meth:`~flagwrap.body.solver.LaggedScreening.memory`)."""
        return self._lagged.memory()

    def restore_solver_memory(self, memory) -> None:
        self._lagged.restore(memory)

    def near_field_blocks(self, x, width: int):
        return self._free.near_field_blocks(x, width)

    def apply(self, x, F):
        F = np.ascontiguousarray(F, dtype=np.float64)
        if not self.matrix_free:
            C = self._cross(x)
            lam = self._solver.solve(C.T @ F.ravel())
            return self._free.apply(x, F) - (C @ lam).reshape(-1, 3)
        # the Krylov blob solver: M_bf F and M_fb lambda as products, never the (3n, 3m)
        # block, so that memory stays linear in beads + blobs (docs/bundle.md, "Cost")
        x = np.ascontiguousarray(x, dtype=np.float64)
        nb, m = len(x), len(self.blobs)
        ub, ux, empty = np.empty((m, 3)), np.empty((nb, 3)), np.empty((0, 3))
        rpy_cross_apply(x, self.radius, self.blobs, self.blob_radii, empty, F, ux, ub)
        if self.wall is not None:
            ub += wall_correction_apply(self.wall, self.blobs, self.blob_radii, x, self.radius, F)
        lam = np.ascontiguousarray(self._solver.solve(ub.ravel()).reshape(m, 3))
        rpy_cross_apply(x, self.radius, self.blobs, self.blob_radii, lam, empty, ux, ub)
        if self.wall is not None:
            ux += wall_correction_apply(self.wall, x, self.radius, self.blobs, self.blob_radii, lam)
        return self._free.apply(x, F) - ux

    apply_single = apply
