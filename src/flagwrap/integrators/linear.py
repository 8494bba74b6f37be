"""Linear solvers for the Rosenbrock stage equations ``W u = r``, ``W = I - gamma h Mob J``.

* :class:`DenseW` assembles ``W`` (ny x ny) and LU-factorises it once per step: fastest for
  short chains (N ~ 60 -> ny ~ 240), O(N^3) time and O(N^2) memory.
* :class:`KrylovW` never forms a dense matrix: ``J`` is sparse (banded, from the coloured
  Jacobian), ``Mob`` is applied matrix-free (O(N^2) RPY product, O(N) memory) and GMRES is
  preconditioned by the near-field operator ``I - gamma h Mob_near J`` (sparse LU). It solves
  to a relative residual ``rtol = 1e-3``: the stage increments are ~|dy| per step ~1e-3 L, so
  the solve error (~1e-6 L) stays below the step tolerance 1e-5 L. Measured on the long
  chain (benchmarks/scaling.py's, 0.01 turn): the same accepted steps as the exact LU (N =
  500: 60 vs 59), free end equal to 1e-5 L, 6-8 GMRES iterations per stage (~150 at rtol
  1e-10). The preconditioner keeps the near-field hydrodynamics (bead pairs within
  ``4a/b + 4`` along the chain), which governs the stiff short-wavelength modes.
* :class:`NearW` drops the far field from ``W`` altogether (a W-method keeps its order for
  any ``W``): one sparse LU and one full ``Mob F`` per stage. Its error estimate is looser and
  the long-wavelength stretching modes, whose relaxation the far field speeds up, limit its
  step: ~15x the steps of the exact ``W`` (N = 500: 846 steps + 292 rejections vs 59 + 18),
  so it lost to KrylovW everywhere measured; kept as an option.
* :class:`BandedW` (default with HI off) and :class:`SparseW` are exact LUs for a local
  mobility: banded, O(N).

``make_w(kind, ...)`` picks one; ``"auto"``: banded with HI off, dense up to
``AUTO_CROSSOVER_NY`` unknowns, krylov above. The crossover is measured (0.01-0.5 turn of the
long chain, same steps both ways): N = 61 dense 2.0 s vs krylov 5.1 s; N = 120 2.7 vs 2.5 s;
N = 250 2.2 vs 1.1 s; N = 500 50 vs 6.0 s (docs/numerics.md).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

AUTO_CROSSOVER_NY = 500


class SingularW(Exception):
    pass


class DenseW:
    """Dense LU of ``W``, assembled straight from the sparse Jacobian triplets.

    The kernel writes ``W^T`` row by row in C order, which is ``W`` in Fortran order: LAPACK
    factorises that buffer in place, without the transposing copy a C-ordered ``W`` needs.
    """

    def __init__(self, system, y, base, G0, gamma_h):
        from flagwrap._system_kernels import w_transpose_dense

        rows, cols, vals = system.force_jacobian_coo(y, base, G0)
        Mxx, mt = system.mobility_blocks(y)
        WT = np.empty((system.ny, system.ny))
        w_transpose_dense(rows, cols, vals, Mxx, mt, gamma_h, WT)
        try:
            self.lu = sla.lu_factor(WT.T, overwrite_a=True, check_finite=False)
        except (ValueError, np.linalg.LinAlgError) as exc:
            raise SingularW(str(exc)) from None
        if not np.all(np.isfinite(self.lu[0])):
            raise SingularW("non-finite LU")

    def solve(self, rhs):
        return sla.lu_solve(self.lu, rhs, check_finite=False)


def _near_field_lu(system, y, J, gamma_h, width=None):
    """Sparse LU of the near-field ``I - gamma h Mob_near J`` (``J`` sparse): the GMRES
    preconditioner of :class:`KrylovW` and the whole ``W`` of :class:`NearW`."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    Mnear = system.near_field_mobility(y, width)
    try:
        return spla.splu(sp.identity(system.ny, format="csc") - gamma_h * (Mnear @ J).tocsc())
    except RuntimeError as exc:
        raise SingularW(str(exc)) from None


class KrylovW:
    """Matrix-free ``W`` with a sparse near-field preconditioner (GMRES, relative tol ``rtol``)."""

    def __init__(self, system, y, base, G0, gamma_h, rtol=1e-3, maxiter=200):
        import scipy.sparse.linalg as spla

        self.system = system
        self.y = y
        self.gh = gamma_h
        self.rtol = rtol
        self.maxiter = maxiter
        self.J = system.force_jacobian_sparse(y, base, G0)
        self.P = _near_field_lu(system, y, self.J, gamma_h)
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
    full mobility through ``f``. The far field is not negligible on the long-wavelength
    stretching modes, though, so the step controller takes ~15x the steps of the exact ``W``
    (module docstring). Cost per step: one sparse banded LU, O(N) in time and memory, plus one
    full ``Mob F`` per stage. ``width`` (beads along the chain kept in ``Mob_near``) defaults
    to :meth:`RodSystem.near_field_mobility`'s overlap range + 4.
    """

    def __init__(self, system, y, base, G0, gamma_h, width=None):
        self.lu = _near_field_lu(system, y, system.force_jacobian_sparse(y, base, G0), gamma_h,
                                 width)

    def solve(self, rhs):
        u = self.lu.solve(rhs)
        if not np.all(np.isfinite(u)):
            raise SingularW("non-finite solve")
        return u


def _band_structure(system, rows, cols):
    """Reverse Cuthill-McKee order of the Jacobian pattern without the motor angle, and the
    bandwidths (kl, ku) it gives.

    The pattern is fixed for a system (coloured differences and the analytic stretching block
    give the same triplets every call; only the motor-angle column's non-zeros vary and it is
    not part of the band), so it is computed once and cached on the system.
    """
    cached = getattr(system, "_band_cache", None)
    if cached is not None:
        return cached
    import scipy.sparse as sp
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    n = system.ny - 1
    keep = (rows < n) & (cols < n)
    A = sp.csr_matrix((np.ones(int(keep.sum())), (rows[keep], cols[keep])), shape=(n, n))
    A = A + A.T + sp.identity(n, format="csr")
    perm = np.asarray(reverse_cuthill_mckee(A.tocsr(), symmetric_mode=True), dtype=np.int64)
    inv = np.empty_like(perm)
    inv[perm] = np.arange(n)
    r, c = inv[rows[keep]], inv[cols[keep]]
    kl = int(max(0, (r - c).max()))
    ku = int(max(0, (c - r).max()))
    system._band_cache = (perm, inv, kl, ku)
    return system._band_cache


class BandedW:
    """LAPACK banded LU (dgbtrf/dgbtrs) of ``W`` for a local mobility, exact, O(N).

    The motor angle ``phi`` is the last unknown; no force depends on it through ``J``'s rows
    (``dphi/dt = omega`` is prescribed), so ``W``'s last row is ``e_phi`` and its last column
    ``w`` only feeds the others: ``u_phi = r_phi``, ``W' u' = r' - w u_phi``. ``W'`` (beads and
    twists) is reordered by reverse Cuthill-McKee, which interleaves beads and twists along
    the chain and makes it banded (half-bandwidths ~10): factorising costs O(N kl (kl + ku))
    without sparse-LU bookkeeping. Used with HI off; exact.
    """

    def __init__(self, system, y, base, G0, gamma_h):
        from scipy.linalg.lapack import dgbtrf

        from flagwrap._system_kernels import band_from_triplets

        if system.mobility.long_range:
            raise ValueError("BandedW needs a local mobility (numerics.hydrodynamics = false)")
        rows, cols, vals = system.force_jacobian_coo(y, base, G0)
        perm, inv, kl, ku = _band_structure(system, rows, cols)
        n = system.ny - 1
        ab = np.empty((2 * kl + ku + 1, n), order="F")
        self.w = np.empty(n)
        band_from_triplets(rows, cols, vals, system.local_mobility_diagonal(), gamma_h, inv,
                           kl, ku, n, ab, self.w)
        lu, piv, info = dgbtrf(ab, kl, ku, overwrite_ab=1)
        if info != 0 or not np.all(np.isfinite(lu)):
            raise SingularW(f"banded LU failed (info {info})")
        self.lu, self.piv, self.kl, self.ku, self.perm, self.n = lu, piv, kl, ku, perm, n

    def solve(self, rhs):
        from scipy.linalg.lapack import dgbtrs

        n = self.n
        u_phi = rhs[n]
        x, info = dgbtrs(self.lu, self.kl, self.ku, (rhs[:n] - self.w * u_phi)[self.perm], self.piv)
        if info != 0:
            raise SingularW(f"banded solve failed (info {info})")
        out = np.empty(n + 1)
        out[self.perm] = x
        out[n] = u_phi
        return out


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
            kind = "banded"
        else:
            kind = "dense" if system.ny <= AUTO_CROSSOVER_NY else "krylov"
    if kind == "banded":
        return BandedW(system, y, base, G0, gamma_h)
    if kind == "sparse":
        return SparseW(system, y, base, G0, gamma_h)
    if kind == "dense":
        return DenseW(system, y, base, G0, gamma_h)
    if kind == "krylov":
        return KrylovW(system, y, base, G0, gamma_h)
    if kind == "near":
        return NearW(system, y, base, G0, gamma_h)
    raise ValueError(f"unknown linear solver {kind!r}")
