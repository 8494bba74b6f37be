"""Linear solvers for the Rosenbrock stage equations ``W u = r``, ``W = I - gamma h Mob J``.

* :class:`DenseW` assembles ``W`` (ny x ny) and LU-factorises it once per step: fastest for
  small chains (N ~ 60 -> ny ~ 240), O(N^3) time and O(N^2) memory.
* :class:`KrylovW` never forms a dense matrix: ``J`` is sparse (banded, from the coloured
  Jacobian), ``Mob`` is applied matrix-free (O(N^2) RPY product, O(N) memory) and GMRES is
  preconditioned by the near-field operator ``I - gamma h Mob_near J`` (sparse LU). Used for
  long chains. The preconditioner keeps the near-field hydrodynamics (bead pairs within
  ``4a/b + 4`` along the chain), which governs the stiff short-wavelength modes: with the self
  mobility alone GMRES needed >100 iterations at N = 241 (overlapping beads).

* :class:`SparseW` is the exact sparse LU when the mobility is local (HI off): banded, O(N).

``make_w(kind, ...)`` picks one; ``"auto"`` switches at ``ny > 4000`` (N ~ 1000), a crossover
measured in benchmarks/scaling.py.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

AUTO_CROSSOVER_NY = 4000


class SingularW(Exception):
    pass


class DenseW:
    def __init__(self, system, y, base, G0, gamma_h):
        J = system.force_jacobian(y, base, G0)
        Mxx, mt = system.mobility_blocks(y)
        # W = I - gamma h Mob J with Mob = blockdiag(Mxx, diag(mt), 0): multiply by blocks only
        n3, ne = Mxx.shape[0], mt.shape[0]
        W = np.empty_like(J)
        np.matmul(Mxx, J[:n3], out=W[:n3])
        np.multiply(mt[:, None], J[n3:n3 + ne], out=W[n3:n3 + ne])
        W[n3 + ne:] = 0.0
        W *= -gamma_h
        W.flat[:: W.shape[0] + 1] += 1.0
        try:
            self.lu = sla.lu_factor(W, overwrite_a=True, check_finite=False)
        except (ValueError, np.linalg.LinAlgError) as exc:
            raise SingularW(str(exc)) from None
        if not np.all(np.isfinite(self.lu[0])):
            raise SingularW("non-finite LU")

    def solve(self, rhs):
        return sla.lu_solve(self.lu, rhs, check_finite=False)


class KrylovW:
    """Matrix-free ``W`` with a sparse local-drag preconditioner (GMRES, relative tol ``rtol``)."""

    def __init__(self, system, y, base, G0, gamma_h, rtol=1e-10, maxiter=200):
        import scipy.sparse as sp
        import scipy.sparse.linalg as spla

        self.system = system
        self.y = y
        self.gh = gamma_h
        self.rtol = rtol
        self.maxiter = maxiter
        self.J = system.force_jacobian_sparse(y, base, G0)
        Mnear = system.near_field_mobility(y)
        P = sp.identity(system.ny, format="csc") - gamma_h * (Mnear @ self.J).tocsc()
        try:
            self.P = spla.splu(P)
        except RuntimeError as exc:
            raise SingularW(str(exc)) from None
        n = system.ny
        self.A = spla.LinearOperator((n, n), matvec=self._matvec, dtype=float)
        self.M = spla.LinearOperator((n, n), matvec=self.P.solve, dtype=float)
        self.iterations = 0

    def _matvec(self, v):
        return v - self.gh * self.system.apply_mobility(self.y, self.J @ v)

    def solve(self, rhs):
        import scipy.sparse.linalg as spla

        count = [0]

        def cb(_):
            count[0] += 1

        u, info = spla.gmres(self.A, rhs, M=self.M, rtol=self.rtol, atol=0.0, restart=50,
                             maxiter=self.maxiter, callback=cb, callback_type="pr_norm")
        self.iterations += count[0]
        if info != 0:
            raise SingularW(f"GMRES did not converge ({info})")
        return u


class NearW:
    """Approximate ``W = I - gamma h Mob_near J`` with the chain-local hydrodynamics only.

    ROS34PW2 and ROS2 are *W-methods*: their order holds for any ``W`` (Rang & Angermann
    2005), so ``W`` may drop the far-field hydrodynamics while every stage still sees the
    full mobility through ``f``. What is dropped only matters for stability on the stiff
    modes, and those are short-wavelength (bond stretch, twist, one-bond bending) whose
    forces alternate in sign along the chain, so their far field cancels. Cost per step:
    one sparse banded LU, O(N) in time and memory, plus one full ``Mob F`` per stage.
    ``width`` (beads along the chain kept in ``Mob_near``) defaults to
    :meth:`RodSystem.near_field_mobility`'s overlap range + 4.
    """

    def __init__(self, system, y, base, G0, gamma_h, width=None):
        import scipy.sparse as sp
        import scipy.sparse.linalg as spla

        J = system.force_jacobian_sparse(y, base, G0)
        Mnear = system.near_field_mobility(y, width)
        W = sp.identity(system.ny, format="csc") - gamma_h * (Mnear @ J).tocsc()
        try:
            self.lu = spla.splu(W)
        except RuntimeError as exc:
            raise SingularW(str(exc)) from None

    def solve(self, rhs):
        u = self.lu.solve(rhs)
        if not np.all(np.isfinite(u)):
            raise SingularW("non-finite solve")
        return u


class SparseW:
    """Sparse direct solve for a local (diagonal) mobility: ``W`` is banded, O(N) to factorise.

    Exact when the long-range hydrodynamics is off (the paper's "without HIs" runs).
    """

    def __init__(self, system, y, base, G0, gamma_h):
        import scipy.sparse as sp
        import scipy.sparse.linalg as spla

        if system.mobility.long_range:
            raise ValueError("SparseW needs a local mobility (numerics.hydrodynamics = false)")
        rows, cols, vals = system.force_jacobian_coo(y, base, G0)
        d = system.local_mobility_diagonal()
        n = system.ny
        # W = I - gamma h diag(d) J assembled straight from the triplets (duplicates add)
        diag = np.arange(n)
        W = sp.csc_matrix((np.concatenate([-gamma_h * d[rows] * vals, np.ones(n)]),
                           (np.concatenate([rows, diag]), np.concatenate([cols, diag]))),
                          shape=(n, n))
        try:
            self.lu = spla.splu(W)
        except RuntimeError as exc:
            raise SingularW(str(exc)) from None

    def solve(self, rhs):
        return self.lu.solve(rhs)


def make_w(kind, system, y, base, G0, gamma_h):
    if kind == "auto":
        if not system.mobility.long_range:
            kind = "sparse"
        else:
            kind = "dense" if system.ny <= AUTO_CROSSOVER_NY else "krylov"
    if kind == "sparse":
        return SparseW(system, y, base, G0, gamma_h)
    if kind == "dense":
        return DenseW(system, y, base, G0, gamma_h)
    if kind == "krylov":
        return KrylovW(system, y, base, G0, gamma_h)
    if kind == "near":
        return NearW(system, y, base, G0, gamma_h)
    raise ValueError(f"unknown linear solver {kind!r}")
