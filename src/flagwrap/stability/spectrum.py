"""Linear stability of a steady state: eigenvalues of the turning-frame Jacobian.

The perturbations of a steady state obey ``d(dz)/dt = J dz``, with ``J`` from
:meth:`flagwrap.system.rotating.RotatingFrame.jacobian`. The state is stable when every
eigenvalue has a negative real part. The spectrum spans many decades: stretching modes decay at
~1e7 omega, the slowest bending and whirling modes at ~0.01-1 omega. Only the eigenvalues of
largest real part matter.

* ``method="dense"``: all eigenvalues (LAPACK ``geev``; ~30 ms at the paper's N = 61, n = 236
  unknowns). The eigenvalues are backward stable to ``eps ||J||``, ~1e-8 omega for the
  leading ones here.
* ``method="arnoldi"``: the ``k`` eigenvalues nearest ``sigma`` by shift-invert Arnoldi
  (ARPACK through :func:`scipy.sparse.linalg.eigs`, one LU of ``J - sigma I``), for long
  chains. The slow modes are the ones nearest 0, so ``sigma = 0`` finds them.
* ``"auto"``: dense up to ``DENSE_MAX`` unknowns.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

DENSE_MAX = 1500


@dataclass
class Spectrum:
    """Eigenvalues (units of omega) sorted by decreasing real part (of a conjugate pair, the
    one with positive imaginary part first); ``vectors[:, k]`` is the mode of ``values[k]``
    (``None`` unless asked)."""

    values: np.ndarray
    vectors: np.ndarray | None = None

    @property
    def leading(self) -> complex:
        return complex(self.values[0])

    @property
    def stable(self) -> bool:
        return self.values[0].real < 0.0


def _sorted(w, V=None):
    order = np.lexsort((-w.imag, -w.real))
    return Spectrum(w[order], None if V is None else V[:, order])


def spectrum(frame, state, vectors: bool = False, method: str = "auto", k: int = 12,
             sigma: float = 0.0) -> Spectrum:
    """Eigenvalues of the Jacobian at ``state`` (:class:`~flagwrap.stability.steady.SteadyState`)."""
    import scipy.linalg as sl

    J = frame.jacobian(state.z, state.base, state.machin, state.info)
    if method == "auto":
        method = "dense" if J.shape[0] <= DENSE_MAX else "arnoldi"
    if method == "dense":
        if vectors:
            w, V = sl.eig(J, check_finite=False)
            return _sorted(w, V)
        return _sorted(sl.eigvals(J, check_finite=False))
    if method == "arnoldi":
        from scipy.sparse.linalg import LinearOperator, eigs

        n = J.shape[0]
        lu = sl.lu_factor(J - sigma * np.eye(n), check_finite=False)
        op = LinearOperator((n, n), matvec=lambda v: sl.lu_solve(lu, v), dtype=float)
        mu, V = eigs(op, k=min(k, n - 2), which="LM")
        w = sigma + 1.0 / mu
        return _sorted(w, V if vectors else None)
    raise ValueError(f"method must be 'auto', 'dense' or 'arnoldi', got {method!r}")


def mode_vector(frame, vector: np.ndarray) -> np.ndarray:
    """A mode as a complex vector over the unknowns ``z``, scaled to a largest bead
    displacement of 1 with that bead's displacement as real as a complex vector can be."""
    v = np.asarray(vector, complex)
    d = v[: frame.n3].reshape(-1, 3)
    amp = np.linalg.norm(d, axis=1)
    i = int(np.argmax(amp)) if amp.size else 0
    if not amp.size or amp[i] == 0:
        return v
    ph = np.angle(np.sum(d[i] * d[i])) / 2.0
    return v * np.exp(-1j * ph) / amp[i]


def mode_positions(frame, vector: np.ndarray) -> np.ndarray:
    """The position part of :func:`mode_vector` as ``(N, 3)`` complex displacements (zero on
    the clamped beads)."""
    s = frame.system
    d = np.zeros((s.N, 3), complex)
    d[s.nc:] = mode_vector(frame, vector)[: frame.n3].reshape(-1, 3)
    return d
