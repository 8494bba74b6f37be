"""A bead chain that drags like a slender tube of the filament's radius
(``filament.hydrodynamic_model = "tube"``; docs/bacterium.md, "The chain matched to a tube").

A chain of RPY spheres of radius ``a_h`` spaced ``b`` apart is, to the slender-body order, a
body with *two* radii: ``r_par`` for motion along the chain and ``r_perp`` across it
(:func:`flagwrap.theory.slender_body.chain_effective_radii`, from the infinite chain's
neighbour sums):

    ln(r_par / b)  = ln 2 - 1/2 - b/(3 a_h)  - gamma + (2/3) zeta(3) (a_h/b)^2,
    ln(r_perp / b) = ln 2 + 1/2 - 2b/(3 a_h) - gamma - (2/3) zeta(3) (a_h/b)^2.

Both fall far below the filament's radius ``a`` when ``a_h = a`` and ``b >> a`` (the
bacterial examples' ``b = 6.5 a``: ``r_par = 0.52 a``, ``r_perp = 0.16 a``), and no single
``a_h`` makes both equal ``a`` (their ratio is at least 1.07). Two parameters do:

* ``a_h`` solves ``r_perp(a_h, b) = a`` (the normal drag, which sets the torque and most of
  the propulsion);
* the bead's self-mobility along the chain's tangent ``t`` is raised,
  ``1/(6 pi a_h) (I + kappa t t)``, which adds ``(4/3) kappa b / a_h`` to the axial local term
  ``8 pi u / f`` and so lowers ``ln r_par`` by ``kappa b / (3 a_h)``: ``kappa = 3 (a_h/b)
  ln(r_par(a_h, b) / a) >= 0``, making ``r_par = a``.

Adding a positive semi-definite block diagonal to the RPY matrix keeps the mobility
symmetric positive definite. The correction is a local (self) term, like the local term of
slender-body theory: it does not radiate to other beads or to a body's blobs. The tangent of
bead ``i`` is the central difference ``x_{i+1} - x_{i-1}`` of its chain's free beads
(one-sided at the chain's ends), so the mobility is rotation covariant,
``M(R x) = R M(x) R^T``. The matched chain needs ``b >= TUBE_MIN_BOND a`` (2.51 a: at touching
beads, ``a_h = b/2``, ``r_perp = 0.399 b``).
"""

from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numba as nb
import numpy as np

from flagwrap.hydrodynamics.mobility import Mobility


class TubeChain(NamedTuple):
    """The matched chain: bead radius ``a_h``, tangential self-mobility factor ``kappa`` and,
    for the record, the sphere chain's two radii at that ``a_h`` (before the correction)."""

    bead_radius: float
    kappa: float
    r_par: float
    r_perp: float


def _radii(ah: float, b: float) -> tuple[float, float]:
    from flagwrap.theory.slender_body import chain_effective_radii

    return chain_effective_radii(ah, b)


#: the smallest ``b / a`` the matched chain reaches with non-overlapping beads (``a_h = b/2``)
TUBE_MIN_BOND = 1.0 / _radii(0.5, 1.0)[1]


@functools.lru_cache(maxsize=64)
def tube_chain(radius: float, spacing: float) -> TubeChain:
    """``(a_h, kappa, r_par, r_perp)`` of the chain of spacing ``b`` matched to a tube of radius
    ``a`` (module docstring); any consistent length unit. ``b < TUBE_MIN_BOND a``: ValueError."""
    from scipy.optimize import brentq

    a, b = float(radius), float(spacing)
    if not (a > 0 and b > 0):
        raise ValueError(f"tube_chain: radius and spacing must be positive, got {a!r}, {b!r}")
    if b < TUBE_MIN_BOND * a * (1 - 1e-12):
        raise ValueError(f"tube_chain: spacing {b:g} is below {TUBE_MIN_BOND:.4g} x radius {a:g}")
    # r_perp grows monotonically with a_h (its self term -2b/(3 a_h) dominates): bracket it
    g = lambda x: math.log(_radii(x * b, b)[1] / a)  # noqa: E731
    x = 0.5 if g(0.5) <= 0 else brentq(g, 1e-3, 0.5, xtol=1e-15, rtol=1e-15)
    ah = x * b
    rp, rn = _radii(ah, b)
    return TubeChain(ah, 3.0 * x * math.log(rp / a), rp, rn)


@nb.njit(cache=True)
def _tangent(x, i, s, e):
    lo = i - 1 if i > s else i
    hi = i + 1 if i < e - 1 else i
    d0 = x[hi, 0] - x[lo, 0]
    d1 = x[hi, 1] - x[lo, 1]
    d2 = x[hi, 2] - x[lo, 2]
    n = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    if n == 0.0:
        return 0.0, 0.0, 0.0
    return d0 / n, d1 / n, d2 / n


@nb.njit(cache=True)
def tube_apply_add(x, F, chains, c, out):
    """``out_i += c t_i (t_i . F_i)`` for the beads of every chain ``[chains[k,0], chains[k,1])``."""
    for k in range(chains.shape[0]):
        s, e = chains[k, 0], chains[k, 1]
        if e - s < 2:
            continue
        for i in range(s, e):
            t0, t1, t2 = _tangent(x, i, s, e)
            p = c * (t0 * F[i, 0] + t1 * F[i, 1] + t2 * F[i, 2])
            out[i, 0] += p * t0
            out[i, 1] += p * t1
            out[i, 2] += p * t2


@nb.njit(cache=True)
def tube_self_blocks(x, chains, c, out):
    """``out[i] = c t_i t_i^T`` for the beads of the chains, 0 elsewhere; ``out`` (n, 3, 3)."""
    out[:] = 0.0
    for k in range(chains.shape[0]):
        s, e = chains[k, 0], chains[k, 1]
        if e - s < 2:
            continue
        for i in range(s, e):
            t = _tangent(x, i, s, e)
            for p in range(3):
                for q in range(3):
                    out[i, p, q] = c * t[p] * t[q]


class TubeMobility(Mobility):
    """``inner`` (any mobility of the free beads: free space, beside a fixed body, any backend)
    plus the tube's tangential self term ``kappa/(6 pi a_h) t t`` on the beads of ``chains``
    (``(start, stop)`` index ranges of the free beads, one per filament). Every other
    attribute is ``inner``'s."""

    def __init__(self, inner, chains, kappa: float):
        self.inner = inner
        self.kappa = float(kappa)
        self.chains = np.ascontiguousarray(np.asarray(chains, dtype=np.int64).reshape(-1, 2))
        self.radius = inner.radius
        self.long_range = inner.long_range
        self._c = self.kappa / (6.0 * math.pi * self.radius)
        if hasattr(inner, "stage_matrix"):
            self.stage_matrix = self._stage_matrix

    def __getattr__(self, name):  # backend, axisymmetric, matrix_free, solver memory, ...
        if name == "inner":
            raise AttributeError(name)
        return getattr(self.inner, name)

    def _add(self, x, v, F):
        tube_apply_add(np.ascontiguousarray(x, dtype=np.float64),
                       np.ascontiguousarray(F, dtype=np.float64), self.chains, self._c, v)
        return v

    def apply(self, x, F):
        return self._add(x, np.array(self.inner.apply(x, F), dtype=np.float64), F)

    def apply_single(self, x, F):
        return self._add(x, np.array(self.inner.apply_single(x, F), dtype=np.float64), F)

    def _blocks(self, x):
        x = np.ascontiguousarray(x, dtype=np.float64)
        out = np.empty((len(x), 3, 3))
        tube_self_blocks(x, self.chains, self._c, out)
        return out

    def _add_blocks(self, x, M):
        n = len(x)
        i = np.arange(n)
        view = M.reshape(n, 3, n, 3)
        if not np.shares_memory(view, M):  # pragma: no cover - inner matrices are contiguous
            raise ValueError("TubeMobility: the inner matrix must be C-contiguous")
        view[i, :, i, :] += self._blocks(x)
        return M

    def matrix(self, x, out=None):
        return self._add_blocks(x, self.inner.matrix(x, out=out))

    def _stage_matrix(self, x, out=None):
        return self._add_blocks(x, self.inner.stage_matrix(x, out=out))

    def near_field_blocks(self, x, width: int):
        out = self.inner.near_field_blocks(x, width)
        out[:, (out.shape[1] - 1) // 2] += self._blocks(x)
        return out
