"""The Rotne-Prager-Yamakawa mobility of spheres of different radii (filament beads and body
blobs together).

Zuk, Wajnryb, Mizerski & Szymczak, "Rotne-Prager-Yamakawa approximation for different-sized
particles in application to macromolecular bead models", J. Fluid Mech. 741, R5 (2014),
Eqs. (10)-(12), viscosity 1. For spheres i, j of radii ``a_i``, ``a_j`` at distance ``r``:

* apart (``r > a_i + a_j``):
  ``mu_ij = 1/(8 pi r) [(1 + (a_i^2 + a_j^2)/(3 r^2)) I + (1 - (a_i^2 + a_j^2)/r^2) rr]``;
* overlapping (``|a_i - a_j| < r <= a_i + a_j``):
  ``mu_ij = 1/(6 pi a_i a_j) [(16 r^3 (a_i + a_j) - ((a_i - a_j)^2 + 3 r^2)^2)/(32 r^3) I
  + 3 ((a_i - a_j)^2 - r^2)^2/(32 r^3) rr]``;
* one inside the other (``r <= |a_i - a_j|``): ``mu_ij = I / (6 pi max(a_i, a_j))``;
* self: ``I / (6 pi a_i)``.

With equal radii these are the equal-size RPY tensor of :mod:`flagwrap.hydrodynamics._kernels`
(tested to rounding). The matrix is positive definite for every configuration, which is the
reason for this regularisation (Zuk et al.). It is continuous at ``r = a_i + a_j`` and at
``r = |a_i - a_j|``.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from flagwrap.hydrodynamics._kernels import add_pair_product, store_pair_block


@nb.njit(cache=True, inline="always")
def _pair(r, ai, aj):
    """``(f, g)`` with ``mu_ij = f I + g rr`` (viscosity 1)."""
    if r > ai + aj:
        s2 = (ai * ai + aj * aj) / (r * r)
        c = 1.0 / (8.0 * math.pi * r)
        return c * (1.0 + s2 / 3.0), c * (1.0 - s2)
    d = ai - aj
    if r > abs(d):
        c = 1.0 / (6.0 * math.pi * ai * aj * 32.0 * r * r * r)
        q = d * d + 3.0 * r * r
        e = d * d - r * r
        return c * (16.0 * r * r * r * (ai + aj) - q * q), c * 3.0 * e * e
    return 1.0 / (6.0 * math.pi * max(ai, aj)), 0.0


@nb.njit(cache=True, inline="always")
def _sep(p, i, q, j):
    """``(d0, d1, d2, r)``: the vector from ``q[j]`` to ``p[i]`` and its length."""
    d0 = p[i, 0] - q[j, 0]
    d1 = p[i, 1] - q[j, 1]
    d2 = p[i, 2] - q[j, 2]
    return d0, d1, d2, math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)


@nb.njit(cache=True)
def rpy_matrix_radii(x, radii, out):
    """Fill ``out`` (3n, 3n) with the mobility of spheres at ``x`` (n, 3) of ``radii`` (n,)."""
    n = x.shape[0]
    for i in range(n):
        store_pair_block(out, i, i, 1.0 / (6.0 * math.pi * radii[i]), 0.0, 0.0, 0.0, 0.0, 0.0,
                         False)
        for j in range(i + 1, n):
            d0, d1, d2, r = _sep(x, i, x, j)
            f, g = _pair(r, radii[i], radii[j])
            store_pair_block(out, i, j, f, g, d0, d1, d2, r, True)


@nb.njit(cache=True)
def rpy_apply_radii(x, radii, F, out):
    """``out = mu F`` for spheres of ``radii`` (O(n^2), no matrix)."""
    n = x.shape[0]
    for i in range(n):
        s = 1.0 / (6.0 * math.pi * radii[i])
        out[i, 0] = s * F[i, 0]
        out[i, 1] = s * F[i, 1]
        out[i, 2] = s * F[i, 2]
    for i in range(n):
        for j in range(i + 1, n):
            d0, d1, d2, r = _sep(x, i, x, j)
            f, g = _pair(r, radii[i], radii[j])
            if r > 0.0:
                u0, u1, u2 = d0 / r, d1 / r, d2 / r
            else:
                u0, u1, u2 = 0.0, 0.0, 0.0
            add_pair_product(out, F, i, j, f, g, u0, u1, u2)


class PolydisperseRPY:
    """RPY mobility of spheres with per-sphere radii (viscosity 1): ``matrix(x)``,
    ``apply(x, F)``."""

    long_range = True

    def __init__(self, radii):
        self.radii = np.ascontiguousarray(radii, dtype=np.float64)
        if not (self.radii.ndim == 1 and np.all(self.radii > 0) and np.all(np.isfinite(self.radii))):
            raise ValueError("radii must be a 1-D array of finite positive numbers")

    def matrix(self, x, out=None):
        x = np.ascontiguousarray(x, dtype=np.float64)
        n = len(x)
        if out is None:
            out = np.empty((3 * n, 3 * n))
        rpy_matrix_radii(x, self.radii, out)
        return out

    def apply(self, x, F):
        x = np.ascontiguousarray(x, dtype=np.float64)
        F = np.ascontiguousarray(F, dtype=np.float64)
        out = np.empty_like(F)
        rpy_apply_radii(x, self.radii, F, out)
        return out


@nb.njit(cache=True)
def rpy_cross_radii(x, a, y, b, out):
    """``out`` (3n, 3m): the mobility block between spheres at ``x`` (radius ``a`` each) and
    spheres at ``y`` of radii ``b`` (m,).

    The free swimmer builds it at every velocity (beads x blobs), so apart pairs, nearly all
    of them, take one square root and one division (``g`` folded into ``d d^T / r^2``): 1.7x
    the speed of the generic pair path, the same to rounding."""
    c8 = 1.0 / (8.0 * math.pi)
    aa = a * a
    for i in range(x.shape[0]):
        xi0, xi1, xi2 = x[i, 0], x[i, 1], x[i, 2]
        k = 3 * i
        for j in range(y.shape[0]):
            d0 = xi0 - y[j, 0]
            d1 = xi1 - y[j, 1]
            d2 = xi2 - y[j, 2]
            r2 = d0 * d0 + d1 * d1 + d2 * d2
            bj = b[j]
            if r2 > (a + bj) * (a + bj):
                ir2 = 1.0 / r2
                c = c8 * math.sqrt(ir2)
                s2 = (aa + bj * bj) * ir2
                f = c * (1.0 + s2 / 3.0)
                g = c * (1.0 - s2) * ir2
            else:
                r = math.sqrt(r2)
                f, g = _pair(r, a, bj)
                g = g / r2 if r > 0.0 else 0.0
            m = 3 * j
            out[k, m] = f + g * d0 * d0
            out[k, m + 1] = g * d0 * d1
            out[k, m + 2] = g * d0 * d2
            out[k + 1, m] = g * d1 * d0
            out[k + 1, m + 1] = f + g * d1 * d1
            out[k + 1, m + 2] = g * d1 * d2
            out[k + 2, m] = g * d2 * d0
            out[k + 2, m + 1] = g * d2 * d1
            out[k + 2, m + 2] = f + g * d2 * d2


@nb.njit(cache=True, inline="always")
def _cross_pair(d0, d1, d2, a, bj):
    """``(f, g)`` of :func:`rpy_cross_radii`'s block ``f I + g d d^T`` for the separation
    ``d``."""
    r2 = d0 * d0 + d1 * d1 + d2 * d2
    if r2 > (a + bj) * (a + bj):
        ir2 = 1.0 / r2
        c = math.sqrt(ir2) / (8.0 * math.pi)
        s2 = (a * a + bj * bj) * ir2
        return c * (1.0 + s2 / 3.0), c * (1.0 - s2) * ir2
    r = math.sqrt(r2)
    f, g = _pair(r, a, bj)
    return f, (g / r2 if r > 0.0 else 0.0)


@nb.njit(cache=True)
def rpy_cross_apply(x, a, y, b, Fy, Fx, ux, uy):
    """The products of :func:`rpy_cross_radii`'s block ``C`` without storing it (memory
    O(n + m), time O(n m)): ``ux = C Fy`` (n, 3), the velocities at ``x`` of forces ``Fy`` on
    the spheres at ``y``, and ``uy = C^T Fx`` (m, 3); either force may be zero-length to skip
    its product. The blocks are symmetric, so ``C^T``'s block (j, i) is ``C``'s (i, j)."""
    do_x = Fy.shape[0] > 0
    do_y = Fx.shape[0] > 0
    if do_x:
        ux[:, :] = 0.0
    if do_y:
        uy[:, :] = 0.0
    for i in range(x.shape[0]):
        for j in range(y.shape[0]):
            d0 = x[i, 0] - y[j, 0]
            d1 = x[i, 1] - y[j, 1]
            d2 = x[i, 2] - y[j, 2]
            f, g = _cross_pair(d0, d1, d2, a, b[j])
            if do_x:
                dF = d0 * Fy[j, 0] + d1 * Fy[j, 1] + d2 * Fy[j, 2]
                ux[i, 0] += f * Fy[j, 0] + g * d0 * dF
                ux[i, 1] += f * Fy[j, 1] + g * d1 * dF
                ux[i, 2] += f * Fy[j, 2] + g * d2 * dF
            if do_y:
                dF = d0 * Fx[i, 0] + d1 * Fx[i, 1] + d2 * Fx[i, 2]
                uy[j, 0] += f * Fx[i, 0] + g * d0 * dF
                uy[j, 1] += f * Fx[i, 1] + g * d1 * dF
                uy[j, 2] += f * Fx[i, 2] + g * d2 * dF


def rpy_cross_block(x, a, blobs, blob_radii) -> np.ndarray:
    """:func:`rpy_cross_radii` for beads at ``x`` (radius ``a``) and ``blobs`` in a new
    (3n, 3m) array."""
    out = np.empty((3 * len(x), 3 * len(blobs)))
    rpy_cross_radii(np.ascontiguousarray(x, dtype=np.float64), a, blobs, blob_radii, out)
    return out
