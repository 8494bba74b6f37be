"""Mobility backends behind one small interface.

A mobility maps forces on the hydrodynamically active beads to their velocities,
``v = (1/eta) mu_hat(x) F``. The core divides by ``M`` instead of ``eta`` (see
:mod:`flagwrap.units`). Backends implement:

* ``apply(x, F) -> V``     matrix-free product, (n,3) -> (n,3)
* ``matrix(x) -> (3n,3n)`` dense matrix (for direct linear solves at small n)

``make_mobility(hydrodynamics, radius)`` picks the backend. Faster (FMM, GPU) backends plug in
here without touching the integrators.
"""

from __future__ import annotations

import math

import numpy as np

from flagwrap.hydrodynamics import _kernels as K


class Mobility:
    """Interface; ``radius`` is the hydrodynamic bead radius in core length units."""

    radius: float
    long_range: bool

    def apply(self, x: np.ndarray, F: np.ndarray) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError

    def matrix(self, x: np.ndarray) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError

    def near_field(self, x: np.ndarray, width: int):
        """Sparse (CSR) part of the mobility between beads at most ``width`` apart."""
        import scipy.sparse as sp

        n = 3 * len(x)
        if not self.long_range:
            return sp.identity(n, format="csr") * self.self_mobility
        r, c, v = K.rpy_band_coo(np.ascontiguousarray(x, dtype=np.float64), self.radius, int(width))
        return sp.csr_matrix((v, (r, c)), shape=(n, n))


class RPYMobility(Mobility):
    """Full Rotne-Prager-Yamakawa mobility (paper, Methods), numba O(n^2)."""

    long_range = True

    def __init__(self, radius: float):
        self.radius = float(radius)
        self.self_mobility = 1.0 / (6.0 * math.pi * self.radius)

    def apply(self, x, F):
        x = np.ascontiguousarray(x, dtype=np.float64)
        F = np.ascontiguousarray(F, dtype=np.float64)
        out = np.empty_like(F)
        K.rpy_apply(x, self.radius, F, out)
        return out

    def matrix(self, x):
        x = np.ascontiguousarray(x, dtype=np.float64)
        n = len(x)
        out = np.empty((3 * n, 3 * n))
        K.rpy_matrix(x, self.radius, out)
        return out


class LocalMobility(Mobility):
    """Self mobility only, ``1/(6 pi a)``: the paper's "without HIs" runs."""

    long_range = False

    def __init__(self, radius: float):
        self.radius = float(radius)
        self.self_mobility = 1.0 / (6.0 * math.pi * self.radius)

    def apply(self, x, F):
        return self.self_mobility * np.asarray(F, dtype=np.float64)

    def matrix(self, x):
        return self.self_mobility * np.eye(3 * len(x))


def make_mobility(hydrodynamics: bool, radius: float) -> Mobility:
    return RPYMobility(radius) if hydrodynamics else LocalMobility(radius)
