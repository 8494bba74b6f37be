"""Numba kernels of the Rotne-Prager-Yamakawa (RPY) mobility.

Dimensionless geometric mobility ``mu_hat = eta * mu`` in units of 1/length (multiply by
``1/eta``, or by ``1/M`` in core units). For beads of radius ``a`` at separation ``r``:

* ``r >= 2a`` (paper, Methods; Rotne & Prager 1969):
  ``1/(8 pi r) [ (1 + 2a^2/(3 r^2)) I + (1 - 2a^2/r^2) rr/r^2 ]``
* ``r < 2a`` (overlap form, Rotne & Prager 1969; Yamakawa 1970):
  ``1/(6 pi a) [ (1 - 9 r/(32 a)) I + 3/(32 a) rr/r ]``
* self: ``1/(6 pi a) I``.

The tensor is continuous at ``r = 2a`` and the 3N x 3N matrix is symmetric positive definite
for every configuration (Wajnryb et al., J. Fluid Mech. 2013).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np


@nb.njit(cache=True, inline="always")
def _pair(r, a):
    """Return (f, g) with mu_hat_ij = f I + g rhat rhat."""
    if r >= 2.0 * a:
        c = 1.0 / (8.0 * math.pi * r)
        q = a * a / (r * r)
        return c * (1.0 + 2.0 * q / 3.0), c * (1.0 - 2.0 * q)
    c = 1.0 / (6.0 * math.pi * a)
    return c * (1.0 - 9.0 * r / (32.0 * a)), c * (3.0 * r / (32.0 * a))


@nb.njit(cache=True)
def rpy_matrix(x, a, out):
    """Fill ``out`` (3n, 3n) with the RPY mobility of positions ``x`` (n, 3)."""
    n = x.shape[0]
    s = 1.0 / (6.0 * math.pi * a)
    for i in range(n):
        for k in range(3):
            for m in range(3):
                out[3 * i + k, 3 * i + m] = s if k == m else 0.0
        for j in range(i + 1, n):
            d0 = x[i, 0] - x[j, 0]
            d1 = x[i, 1] - x[j, 1]
            d2 = x[i, 2] - x[j, 2]
            r = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            f, g = _pair(r, a)
            if r > 0.0:
                u0, u1, u2 = d0 / r, d1 / r, d2 / r
            else:
                u0, u1, u2 = 0.0, 0.0, 0.0
            u = (u0, u1, u2)
            for k in range(3):
                for m in range(3):
                    v = g * u[k] * u[m]
                    if k == m:
                        v += f
                    out[3 * i + k, 3 * j + m] = v
                    out[3 * j + m, 3 * i + k] = v


@nb.njit(cache=True)
def rpy_apply(x, a, F, out):
    """``out = mu_hat F`` matrix-free, O(n^2) time, O(n) memory (F, out: (n, 3))."""
    n = x.shape[0]
    s = 1.0 / (6.0 * math.pi * a)
    for i in range(n):
        out[i, 0] = s * F[i, 0]
        out[i, 1] = s * F[i, 1]
        out[i, 2] = s * F[i, 2]
    for i in range(n):
        for j in range(i + 1, n):
            d0 = x[i, 0] - x[j, 0]
            d1 = x[i, 1] - x[j, 1]
            d2 = x[i, 2] - x[j, 2]
            r = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            f, g = _pair(r, a)
            if r > 0.0:
                g = g / (r * r)
            else:
                g = 0.0
            dj = d0 * F[j, 0] + d1 * F[j, 1] + d2 * F[j, 2]
            di = d0 * F[i, 0] + d1 * F[i, 1] + d2 * F[i, 2]
            out[i, 0] += f * F[j, 0] + g * dj * d0
            out[i, 1] += f * F[j, 1] + g * dj * d1
            out[i, 2] += f * F[j, 2] + g * dj * d2
            out[j, 0] += f * F[i, 0] + g * di * d0
            out[j, 1] += f * F[i, 1] + g * di * d1
            out[j, 2] += f * F[i, 2] + g * di * d2


@nb.njit(cache=True)
def rpy_band_coo(x, a, w):
    """RPY blocks for |i - j| <= w as COO triplets (near-field part, for preconditioners)."""
    n = x.shape[0]
    nnz = 0
    for i in range(n):
        lo = max(0, i - w)
        hi = min(n - 1, i + w)
        nnz += 9 * (hi - lo + 1)
    rows = np.empty(nnz, np.int64)
    cols = np.empty(nnz, np.int64)
    vals = np.empty(nnz)
    k = 0
    s = 1.0 / (6.0 * math.pi * a)
    for i in range(n):
        for j in range(max(0, i - w), min(n - 1, i + w) + 1):
            if i == j:
                for p in range(3):
                    for q in range(3):
                        rows[k] = 3 * i + p
                        cols[k] = 3 * j + q
                        vals[k] = s if p == q else 0.0
                        k += 1
                continue
            d0 = x[i, 0] - x[j, 0]
            d1 = x[i, 1] - x[j, 1]
            d2 = x[i, 2] - x[j, 2]
            r = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            f, g = _pair(r, a)
            u = (d0 / r, d1 / r, d2 / r) if r > 0.0 else (0.0, 0.0, 0.0)
            for p in range(3):
                for q in range(3):
                    rows[k] = 3 * i + p
                    cols[k] = 3 * j + q
                    vals[k] = g * u[p] * u[q] + (f if p == q else 0.0)
                    k += 1
    return rows, cols, vals
