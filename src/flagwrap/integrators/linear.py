"""Linear solvers for the Rosenbrock stage equations ``W u = r``, ``W = I - gamma h Mob J``.

* :class:`DenseW` assembles ``W`` (ny x ny) and LU-factorises it once per step: fastest for
  short chains (N ~ 60 -> ny ~ 240), O(N^3) time and O(N^2) memory.
* :class:`KrylovW` never forms a dense matrix: ``J`` is sparse (banded, from the coloured
  Jacobian), ``Mob`` is applied matrix-free and GCR with subspace recycling across the four
  stages is right-preconditioned by the banded LU of the near-field ``I - gamma h Mob_near J``.
  It stops at a relative residual ``rtol = 1e-3`` once the estimated solution error is also
  below ``KAPPA`` x the step's error tolerance for every unknown (the class docstring says why
  both).
* :class:`NearW` drops the far field from ``W`` altogether (a W-method keeps its order for
  any ``W``): one banded LU and one full ``Mob F`` per stage; its looser ``W`` costs many more
  steps, so it is an option, not a default.
* :class:`BandedW` (default with HI off) and :class:`SparseW` are exact LUs for a local
  mobility: banded, O(N).

``make_w(kind, ...)`` picks one; ``"auto"``: banded with HI off, dense up to
``AUTO_CROSSOVER_NY`` unknowns, krylov above. The crossover, the solvers' accuracy and cost
and the stopping rule are measured in docs/numerics.md ("Long chains").
"""

from __future__ import annotations

import math

import numpy as np
import scipy.linalg as sla

AUTO_CROSSOVER_NY = 400
KAPPA = 0.1  # iterative stage solves stop at kappa x the step's error tolerance


class SingularW(Exception):
    pass


class DenseW:
    """Dense LU of ``W``, assembled straight from the sparse Jacobian triplets.

    ``reuse=True`` (what the integrators ask for through :func:`make_w`) assembles and
    factorises in buffers the system keeps, so a step allocates no ~0.5 MB arrays; the LU is
    then valid until the next reusing ``DenseW`` of the same system (one per step).

    The kernel writes ``W^T`` row by row in C order, which is ``W`` in Fortran order: LAPACK
    factorises that buffer in place, without the transposing copy a C-ordered ``W`` needs.
    """

    def __init__(self, system, y, base, G0, gamma_h, reuse: bool = False, omega=None):
        from flagwrap.system.kernels import w_transpose_dense

        rows, cols, vals = system.force_jacobian_coo(y, base, G0, stage=True)
        Mxx, mt = system.mobility_blocks(y, reuse=reuse, stage=True)
        WT = None
        if reuse:  # one W per step: factorise in the system's buffer (no fresh ~0.5 MB array)
            WT = system.__dict__.get("_wt_buffer")
        if WT is None:
            WT = np.empty((system.ny, system.ny))
            if reuse:
                system._wt_buffer = WT
        w_transpose_dense(rows, cols, vals, Mxx, mt, gamma_h, WT)
        if system.drive.free:
            add_motor_rows(WT, system, y, base, gamma_h, omega)
        self.lu = lu_of_transpose(WT)

    def solve(self, rhs):
        return sla.lu_solve(self.lu, rhs, check_finite=False)


def lu_of_transpose(WT):
    """LU factors of ``W`` given ``WT = W^T`` in C order (``W`` in Fortran order, factorised in
    place); :class:`SingularW` if LAPACK refuses it or the factors are not finite."""
    try:
        lu = sla.lu_factor(WT.T, overwrite_a=True, check_finite=False)
    except (ValueError, np.linalg.LinAlgError) as exc:
        raise SingularW(str(exc)) from None
    if not np.all(np.isfinite(lu[0])):
        raise SingularW("non-finite LU")
    return lu


def add_motor_rows(WT, system, y, base, gamma_h, omega) -> None:
    """The torque motors' rows of ``W = I - gamma h Mob J`` in ``WT = W^T``
    (:meth:`~flagwrap.system.rod_system.RodSystem.motor_jacobian`, one per motor); the force
    Jacobian's motor-angle columns are in ``J`` already."""
    if omega is None:
        raise ValueError("a torque motor's W needs the phase's omega")
    rows = np.atleast_2d(system.motor_jacobian(y, base, omega))
    for k, row in enumerate(rows):
        i = system.i_phi + k
        WT[:, i] = -gamma_h * row
        WT[i, i] += 1.0


def preconditioner_width(system) -> int:
    """Beads along the chain whose mutual mobility the GCR preconditioner keeps.

    A pair k beads apart couples with ~(3/4..3/2) a / (k b) of the self mobility (Oseen,
    transverse..longitudinal), so the preconditioner keeps pairs down to ~10 %: k <= 15 a/b.
    Measured GCR iterations per stage (Fig. 4(a) helix at fixed L, 0.1 turn): a/b = 0.68
    (N = 181) width 1/3/6/8/12: 133/36/8.2/5.7/3.3, ms per step 105/33/11.8/11.1/8.9 (dense
    LU 14.0); a/b = 0.90 (N = 241) width 6/8/12/16/24: 53/30/7.4/3.7/2.8 iterations, 73/47/
    19.2/15.5/17.7 ms (dense 27.5). At a/b = 0.225 (benchmarks/scaling.py's chain) width 1-2
    is best and 4-5 costs ~15 % more per step.
    """
    return max(1, math.ceil(15.0 * system.radius / system.bond))


class KrylovW:
    """Matrix-free ``W`` solved by preconditioned GCR with subspace recycling.

    ``W v = v - gamma h Mob (J v)``: ``J`` sparse (coloured Jacobian), ``Mob`` applied
    matrix-free (O(N^2) direct sum or any backend; O(N) memory). Right preconditioner: the
    banded LU of the near-field ``W`` (:class:`BandedW`, RPY blocks of beads within
    ``width`` along the chain, default :func:`preconditioner_width`). GCR (Eisenstat, Elman
    & Schultz 1983) keeps every search direction ``z`` with ``W z`` orthonormalised, so the
    four stages of a Rosenbrock step, which share ``W``, reuse the earlier stages'
    directions: each solve first projects its right-hand side on them (no product needed)
    and then iterates only on what is left (recycling, as in GCRO: Parks et al., SIAM J.
    Sci. Comput. 28, 1651, 2006).

    ``Mob`` inside the iterations is the single-precision product (1e-6 to 1e-5 relative,
    :meth:`~flagwrap.hydrodynamics.mobility.Mobility.apply_single`): the solve is then one of a
    ``W`` perturbed by that much, which a W-method tolerates, at ~1.9x less cost per product.

    Stopping rule, both: relative residual ``rtol = 1e-3`` (the recursively updated residual,
    equal to the true one in exact arithmetic) and, when the integrator passes ``err_scale``
    (the absolute accuracy it holds each unknown to), an estimated solution error
    ``|P^-1 r| <= kappa err_scale`` per unknown with ``kappa = 0.1`` (CVODE likewise solves
    its Krylov systems to 0.05 x its nonlinear tolerance). Measured on benchmarks/scaling.py's
    chain: at N = 1000 the residual test alone already gives the steps of exact solves (0.03
    turn: 728 steps, 42 ms per step; with both tests 767 steps, 54 ms); at N = 8000 it does
    not: its solve errors, concentrated where the right-hand side is small, drove the step
    from ~5e-5 to ~5e-7 (1/omega) and the error test restores ~2e-5 (0.0002 turn in 175 steps).
    """

    max_vectors = 40  # ~10-16 directions per step (4 stages) measured; restart when full

    def __init__(self, system, y, base, G0, gamma_h, rtol=1e-3, maxiter=200, width=None,
                 err_scale=None, kappa=KAPPA):
        import scipy.sparse as sp

        if width is None:
            width = preconditioner_width(system)
        self.system = system
        self.y = y
        self.gh = gamma_h
        self._gcr_setup(system.ny, rtol, maxiter, err_scale, kappa)
        rows, cols, vals = system.force_jacobian_coo(y, base, G0, nonlocal_terms=False,
                                                     stage=True)
        self.P = BandedW(system, y, base, G0, gamma_h, width=width,
                         triplets=(rows, cols, vals))
        # the product sees every term; the banded preconditioner the chain-local ones
        for r, c, v in system.interaction_jacobian_coo(y, "nonlocal", stage=True):
            rows, cols, vals = (np.concatenate([rows, r]), np.concatenate([cols, c]),
                                np.concatenate([vals, v]))
        self.J = sp.csr_matrix((vals, (rows, cols)), shape=(system.ny, system.ny))

    def _gcr_setup(self, n, rtol, maxiter, err_scale, kappa) -> None:
        """The iteration's state for ``n`` unknowns: the stopping rule (class docstring) and
        the recycled directions. A subclass sets ``P`` (the preconditioner, ``P.solve``) and
        ``matvec``."""
        self.rtol = rtol
        self.maxiter = maxiter
        self.inv_scale = None if err_scale is None else 1.0 / np.asarray(err_scale, float)
        self.kappa = kappa
        self.Z = np.empty((self.max_vectors, n))
        self.C = np.empty((self.max_vectors, n))
        self.k = 0
        self.iterations = 0

    def matvec(self, v):
        # single precision (1e-6..1e-5 relative up to N = 16000, ~1.9x faster from N = 256):
        # far below the 1e-3 the solve stops at; measured N = 1000: 53-55 -> 43 ms per step
        return v - self.gh * self.system.apply_mobility(self.y, self.J @ v, single=True)

    def _converged(self, r, z, bn):
        if float(np.linalg.norm(r)) > self.rtol * bn:
            return False
        # z = P^-1 r estimates the error left in the solution, per unknown
        return self.inv_scale is None or float(np.max(np.abs(z) * self.inv_scale)) <= self.kappa

    def solve(self, rhs):
        bn = float(np.linalg.norm(rhs))
        x = np.zeros_like(rhs)
        if bn == 0.0:
            return x
        r = np.array(rhs, dtype=float)
        k = self.k
        if k:  # minimal-residual start in the recycled space (C orthonormal)
            a = self.C[:k] @ r
            x += a @ self.Z[:k]
            r -= a @ self.C[:k]
        it = 0
        while True:
            z = self.P.solve(r)
            if self._converged(r, z, bn):
                break
            if it >= self.maxiter:
                raise SingularW(f"GCR: residual {np.linalg.norm(r) / bn:.1e} after {it} "
                                "iterations")
            if self.k == self.max_vectors:  # storage full: restart from the current x
                self.k = 0
            c = self.matvec(z)
            it += 1
            k = self.k
            for _ in range(2):  # classical Gram-Schmidt, twice (orthogonal to rounding)
                if k:
                    g = self.C[:k] @ c
                    c -= g @ self.C[:k]
                    z -= g @ self.Z[:k]
            nc = float(np.linalg.norm(c))
            if not np.isfinite(nc) or nc == 0.0:
                raise SingularW("GCR breakdown")
            c /= nc
            z /= nc
            a = float(c @ r)
            x += a * z
            r -= a * c
            self.C[k] = c
            self.Z[k] = z
            self.k = k + 1
        self.iterations += it
        return x


class NearW:
    """Approximate ``W = I - gamma h Mob_near J`` with the chain-local hydrodynamics only.

    ROS34PW2 and ROS2 are *W-methods*: their order holds for any ``W`` (Rang & Angermann
    2005), so ``W`` may drop the far-field hydrodynamics while every stage still sees the
    full mobility through ``f``. The far field is not negligible on the long-wavelength
    stretching modes, though, so the step controller takes ~15x the steps of the exact ``W``
    (module docstring). Cost per step: one banded LU, O(N) in time and memory, plus one
    full ``Mob F`` per stage. ``width`` (beads along the chain kept in ``Mob_near``) defaults
    to the overlapping neighbours (``4a/b`` beads) + 4.
    """

    def __init__(self, system, y, base, G0, gamma_h, width=None):
        if width is None:
            width = int(math.ceil(4 * system.radius / system.bond)) + 4
        self.lu = BandedW(system, y, base, G0, gamma_h, width=width)

    def solve(self, rhs):
        u = self.lu.solve(rhs)
        if not np.all(np.isfinite(u)):
            raise SingularW("non-finite solve")
        return u


def _band_structure(system, rows, cols, width):
    """Reverse Cuthill-McKee order of the pattern of ``Mob_near J`` without the motor angle,
    and the bandwidths (kl, ku) it gives.

    The pattern is fixed for a system and ``width`` (coloured differences and the analytic
    stretching block give the same triplets every call; only the motor-angle column's
    non-zeros vary and it is not part of the band), so it is computed once and cached.
    """
    cache = system.__dict__.setdefault("_band_cache", {})
    if width in cache:
        return cache[width]
    import scipy.sparse as sp
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    n = system.ny - system.layout.block("phi").size
    n3 = 3 * system.nb
    keep = (rows < n) & (cols < n)
    J = sp.csr_matrix((np.ones(int(keep.sum())), (rows[keep], cols[keep])), shape=(n, n))
    beads = sp.diags([np.ones(system.nb - abs(k)) for k in range(-width, width + 1)],
                     list(range(-width, width + 1)))
    M = sp.block_diag((sp.kron(beads, np.ones((3, 3))), sp.identity(n - n3)), format="csr")
    A = M @ J
    A = A + A.T + sp.identity(n, format="csr")
    perm = np.asarray(reverse_cuthill_mckee(A.tocsr(), symmetric_mode=True), dtype=np.int64)
    inv = np.empty_like(perm)
    inv[perm] = np.arange(n)
    A = A.tocoo()
    r, c = inv[A.row], inv[A.col]
    kl = int(max(0, (r - c).max()))
    ku = int(max(0, (c - r).max()))
    cache[width] = (perm, inv, kl, ku)
    return cache[width]


class BandedW:
    """LAPACK banded LU (dgbtrf/dgbtrs) of ``W = I - gamma h Mob_near J``, O(N).

    ``Mob_near``: the mobility between beads at most ``width`` apart along the chain; with
    ``width = 0`` (default) the self mobility only, which *is* the whole mobility with HI off
    (then this LU is exact: the default solver for the paper's "without HIs" runs); with HI
    on it is the preconditioner of :class:`KrylovW` and the ``W`` of :class:`NearW`.

    The motor angles ``phi`` (one per filament) are the last unknowns; no force depends on
    them through ``J``'s rows (``dphi/dt = omega`` is prescribed), so ``W``'s last rows are
    the identity and its last columns ``w`` only feed the others: ``u_phi = r_phi``,
    ``W' u' = r' - w u_phi``. ``W'`` (beads and
    twists) is reordered by reverse Cuthill-McKee, which interleaves beads and twists along
    the chain and makes it banded (half-bandwidths ~10 for ``width = 0``, ~5 more per unit
    of width): factorising costs O(N kl (kl + ku)) without sparse-LU bookkeeping.
    """

    def __init__(self, system, y, base, G0, gamma_h, width=0, triplets=None):
        from scipy.linalg.lapack import dgbtrf

        from flagwrap.system.kernels import band_from_triplets

        rows, cols, vals = triplets or system.force_jacobian_coo(
            y, base, G0, nonlocal_terms=False, stage=True)
        # pairs farther apart than the chain is long do not exist: clamp (short chains)
        width = min(int(width), max(system.nb - 1, 0)) if system.mobility.long_range else 0
        perm, inv, kl, ku = _band_structure(system, rows, cols, width)
        n = system.ny - system.layout.block("phi").size
        Mb, mt = system.near_field_blocks(y, width)
        ab = np.empty((2 * kl + ku + 1, n), order="F")
        self.w = np.empty((n, system.ny - n))
        band_from_triplets(rows, cols, vals, Mb, width, mt, gamma_h, inv, kl, ku, n, ab, self.w)
        lu, piv, info = dgbtrf(ab, kl, ku, overwrite_ab=1)
        if info != 0 or not np.all(np.isfinite(lu)):
            raise SingularW(f"banded LU failed (info {info})")
        self.lu, self.piv, self.kl, self.ku, self.perm, self.n = lu, piv, kl, ku, perm, n

    def solve(self, rhs):
        from scipy.linalg.lapack import dgbtrs

        n = self.n
        u_phi = rhs[n:]
        if len(u_phi) == 1:  # one motor: a column times a number
            r = rhs[:n] - self.w[:, 0] * u_phi[0]
        else:
            r = rhs[:n] - self.w @ u_phi
        x, info = dgbtrs(self.lu, self.kl, self.ku, r[self.perm], self.piv)
        if info != 0:
            raise SingularW(f"banded solve failed (info {info})")
        out = np.empty(len(rhs))
        out[self.perm] = x
        out[n:] = u_phi
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
        rows, cols, vals = system.force_jacobian_coo(y, base, G0, stage=True)
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


def make_w(kind, system, y, base, G0, gamma_h, err_scale=None, omega=None):
    """The stage solver ``kind`` for ``W = I - gamma_h Mob J`` at ``y``; ``err_scale``: the
    absolute accuracy each unknown of a solution needs (iterative solvers stop on it).
    A system with its own stage solver (``system.make_w``, e.g. the free swimmer's) gets it."""
    own = getattr(system, "make_w", None)
    if own is not None:
        return own(kind, y, base, G0, gamma_h, err_scale, omega)
    if system.drive.free:  # the motor's row and column: only the dense W has them
        if kind not in ("auto", "dense"):
            raise ValueError(f"linear solver {kind!r} cannot take a torque motor: use 'dense'")
        return DenseW(system, y, base, G0, gamma_h, reuse=True, omega=omega)
    if kind == "auto":
        if not system.mobility.long_range:
            kind = "banded"
        else:
            kind = "dense" if system.ny <= AUTO_CROSSOVER_NY else "krylov"
    if kind == "banded":
        if system.mobility.long_range:  # the local-mobility LU would be an approximation
            raise ValueError("linear solver 'banded' needs numerics.hydrodynamics = false")
        return BandedW(system, y, base, G0, gamma_h)
    if kind == "sparse":
        return SparseW(system, y, base, G0, gamma_h)
    if kind == "dense":
        return DenseW(system, y, base, G0, gamma_h, reuse=True)
    if kind == "krylov":
        return KrylovW(system, y, base, G0, gamma_h, err_scale=err_scale)
    if kind == "near":
        return NearW(system, y, base, G0, gamma_h)
    raise ValueError(f"unknown linear solver {kind!r}")
