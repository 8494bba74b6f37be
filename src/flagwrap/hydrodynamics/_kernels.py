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
            store_pair_block(out, i, j, f, g, d0, d1, d2, r, True)


@nb.njit(cache=True, inline="always")
def add_pair_product(out, F, i, j, f, g, u0, u1, u2):
    """``out_i += (f I + g uu) F_j`` and ``out_j += (f I + g uu) F_i`` for one pair."""
    uj = u0 * F[j, 0] + u1 * F[j, 1] + u2 * F[j, 2]
    ui = u0 * F[i, 0] + u1 * F[i, 1] + u2 * F[i, 2]
    out[i, 0] += f * F[j, 0] + g * uj * u0
    out[i, 1] += f * F[j, 1] + g * uj * u1
    out[i, 2] += f * F[j, 2] + g * uj * u2
    out[j, 0] += f * F[i, 0] + g * ui * u0
    out[j, 1] += f * F[i, 1] + g * ui * u1
    out[j, 2] += f * F[i, 2] + g * ui * u2


@nb.njit(cache=True, inline="always")
def store_pair_block(out, i, j, f, g, d0, d1, d2, r, symmetric):
    """Write the 3x3 block ``f I + g uu`` (``u = d / r``, 0 for coincident points) of pair
    ``(i, j)`` into ``out`` at rows ``3i``, columns ``3j``, and its transpose at ``(3j, 3i)``
    when ``symmetric``."""
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
            if symmetric:
                out[3 * j + m, 3 * i + k] = v


@nb.njit(cache=True, inline="always")
def _rpy_constants(a):
    """(s, c8, aa, four_aa, kn, kg, floor, one, two_thirds, two): the per-radius constants of
    the pair loops, float64."""
    aa = a * a
    return (1.0 / (6.0 * math.pi * a), 1.0 / (8.0 * math.pi), aa, 4.0 * aa,
            9.0 / (32.0 * a), 3.0 / (32.0 * a), 1e-32 * aa, 1.0, 2.0 / 3.0, 2.0)


@nb.njit(cache=True, inline="always")
def _rpy_constants32(a):
    """The same constants as float32, for :func:`rpy_apply_single` (float32 literals: a float64
    one would promote the whole loop back to float64). The floor keeps ``r^2`` a normal
    float32 (``rsqrt``); for coincident beads the discarded far-field branch overflows to
    inf in float32 and is not selected (only the pair loop uses this, never the self pair)."""
    s, c8, aa, four_aa, kn, kg, floor, one, two_thirds, two = _rpy_constants(a)
    f4 = np.float32
    return (f4(s), f4(c8), f4(aa), f4(four_aa), f4(kn), f4(kg), f4(max(floor, 1e-30)), f4(one),
            f4(two_thirds), f4(two))


def _rpy_pair_coefficients(r2, c):
    """(f, g) with mu_hat_ij = f I + g d d (d = x_i - x_j, r2 = |d|^2), branch-free form of
    :func:`_pair` (see :func:`_rpy_gather_rows`). ``c``: the constants of
    :func:`_rpy_constants`, numeric literals included, so that one function serves float64
    and float32 (numba compiles one version per type)."""
    s, c8, aa, four_aa, kn, kg, floor, one, two_thirds, two = c
    r2 = max(r2, floor)
    ir = one / math.sqrt(r2)
    ir2 = ir * ir
    cf = c8 * ir
    q = aa * ir2
    far = r2 >= four_aa
    f = cf * (one + two_thirds * q) if far else s * (one - kn * r2 * ir)
    g = cf * (one - two * q) * ir2 if far else s * kg * ir
    return f, g


_coef = nb.njit(cache=True, fastmath=True, error_model="numpy", inline="always")(
    _rpy_pair_coefficients)


@nb.njit(cache=True, fastmath=True, error_model="numpy", inline="always")
def _pair_velocity(f, g, d0, d1, d2, F0, F1, F2):
    """``(f I + g d d) F``: the velocity one bead's force gives another."""
    gd = g * (d0 * F0 + d1 * F1 + d2 * F2)
    return f * F0 + gd * d0, f * F1 + gd * d1, f * F2 + gd * d2


def _rpy_gather_rows(xs, ys, zs, a, fx, fy, fz, ox, oy, oz, i0, i1):
    """Rows ``i0 <= i < i1`` of ``mu_hat F`` in structure-of-arrays layout.

    Written so LLVM vectorises the inner loop (AVX2: 4 pairs at once, ~4x the scalar
    symmetric loop measured in benchmarks/scaling.py): every pair is visited from both sides
    (no scatter to ``out[j]``), both RPY branches are computed and one is *selected*, and the
    kernels are compiled with ``error_model="numpy"`` so a division carries no
    ZeroDivisionError branch (that branch alone blocks vectorisation). The self pair
    (r = 0) takes the overlap branch, whose value at r = 0 is exactly the self mobility
    ``1/(6 pi a)``; ``r^2`` is floored at ``1e-32 a^2`` (the self term is then exact to 3e-17, and no term overflows).
    """
    c = _rpy_constants(a)
    n = xs.shape[0]
    for i in range(i0, i1):
        xi = xs[i]
        yi = ys[i]
        zi = zs[i]
        a0 = 0.0
        a1 = 0.0
        a2 = 0.0
        for j in range(n):
            d0 = xi - xs[j]
            d1 = yi - ys[j]
            d2 = zi - zs[j]
            f, g = _coef(d0 * d0 + d1 * d1 + d2 * d2, c)
            v0, v1, v2 = _pair_velocity(f, g, d0, d1, d2, fx[j], fy[j], fz[j])
            a0 += v0
            a1 += v1
            a2 += v2
        ox[i] = a0
        oy[i] = a1
        oz[i] = a2


_rows_serial = nb.njit(cache=True, fastmath=True, error_model="numpy")(_rpy_gather_rows)


@nb.njit(cache=True)
def _soa(x, F):
    n = x.shape[0]
    xs, ys, zs = np.empty(n), np.empty(n), np.empty(n)
    fx, fy, fz = np.empty(n), np.empty(n), np.empty(n)
    for i in range(n):
        xs[i] = x[i, 0]
        ys[i] = x[i, 1]
        zs[i] = x[i, 2]
        fx[i] = F[i, 0]
        fy[i] = F[i, 1]
        fz[i] = F[i, 2]
    return xs, ys, zs, fx, fy, fz


@nb.njit(cache=True)
def _aos(ox, oy, oz, out):
    for i in range(ox.shape[0]):
        out[i, 0] = ox[i]
        out[i, 1] = oy[i]
        out[i, 2] = oz[i]


@nb.njit(cache=True, fastmath=True, error_model="numpy")
def _rpy_apply_serial(x, a, F, out):
    n = x.shape[0]
    xs, ys, zs, fx, fy, fz = _soa(x, F)
    ox, oy, oz = np.empty(n), np.empty(n), np.empty(n)
    _rows_serial(xs, ys, zs, a, fx, fy, fz, ox, oy, oz, 0, n)
    _aos(ox, oy, oz, out)


@nb.njit(cache=True, fastmath=True, error_model="numpy")
def _sym_row(xi, yi, zi, fxi, fyi, fzi, bx, by, bz, bfx, bfy, bfz, tx, ty, tz, c):
    """Pairs of bead i with a block of beads, both ways: returns the sum on i and adds the
    transposed terms to the block's accumulators ``t``. The block arrays are slices passed
    to a separate function, so LLVM vectorises the loop despite the store to ``t[j]``
    (measured: inlined into the caller it ran 2x slower than the gather loop). ``c``: the
    constants of :func:`_rpy_constants` (or ``32``); the sums keep their precision."""
    a0 = c[0] - c[0]  # zero of the working precision
    a1 = a0
    a2 = a0
    for j in range(bx.shape[0]):
        d0 = xi - bx[j]
        d1 = yi - by[j]
        d2 = zi - bz[j]
        f, g = _coef(d0 * d0 + d1 * d1 + d2 * d2, c)
        v0, v1, v2 = _pair_velocity(f, g, d0, d1, d2, bfx[j], bfy[j], bfz[j])
        a0 += v0
        a1 += v1
        a2 += v2
        v0, v1, v2 = _pair_velocity(f, g, d0, d1, d2, fxi, fyi, fzi)  # mu_ji = mu_ij (even in d)
        tx[j] += v0
        ty[j] += v1
        tz[j] += v2
    return a0, a1, a2


@nb.njit(cache=True, fastmath=True, error_model="numpy")
def _sym_sums(xs, ys, zs, fx, fy, fz, c, block):
    """``mu_hat F`` (structure of arrays, in the precision of the inputs and ``c``) visiting
    each pair once (i < j), by column blocks of ``block`` beads."""
    n = xs.shape[0]
    s = c[0]
    ox = s * fx
    oy = s * fy
    oz = s * fz
    tx, ty, tz = np.empty(block, xs.dtype), np.empty(block, xs.dtype), np.empty(block, xs.dtype)
    for j0 in range(0, n, block):
        j1 = min(n, j0 + block)
        m = j1 - j0
        tx[:m] = 0.0
        ty[:m] = 0.0
        tz[:m] = 0.0
        for i in range(j1 - 1):
            lo = 0 if i < j0 else i - j0 + 1  # inside the block: only j > i
            a0, a1, a2 = _sym_row(xs[i], ys[i], zs[i], fx[i], fy[i], fz[i],
                                  xs[j0 + lo:j1], ys[j0 + lo:j1], zs[j0 + lo:j1],
                                  fx[j0 + lo:j1], fy[j0 + lo:j1], fz[j0 + lo:j1],
                                  tx[lo:m], ty[lo:m], tz[lo:m], c)
            ox[i] += a0
            oy[i] += a1
            oz[i] += a2
        ox[j0:j1] += tx[:m]
        oy[j0:j1] += ty[:m]
        oz[j0:j1] += tz[:m]
    return ox, oy, oz


@nb.njit(cache=True, fastmath=True, error_model="numpy")
def _rpy_apply_sym(x, a, F, out, block):
    """``out = mu_hat F`` visiting each pair once (i < j), by column blocks of ``block``
    beads: half the pair evaluations of the gather loop, ~1.5x faster from N ~ 250 (measured
    N = 1000: 0.94 vs 1.41 ms; 16000: 220 vs 361 ms). Serial only."""
    xs, ys, zs, fx, fy, fz = _soa(x, F)
    ox, oy, oz = _sym_sums(xs, ys, zs, fx, fy, fz, _rpy_constants(a), block)
    _aos(ox, oy, oz, out)


@nb.njit(cache=True, fastmath=True, error_model="numpy")
def rpy_apply_single(x, a, F, out, block):
    """``out = mu_hat F`` (float64 in and out) computed in float32: the pair loop of
    :func:`_rpy_apply_sym` with twice the SIMD lanes, ~1.9x faster (measured N = 1000: 0.48
    vs 0.89 ms; 4000: 6.4 vs 13.2 ms).

    For the products inside an iterative solve that stops at a relative residual of 1e-3,
    not for the right-hand side. Accuracy: positions are centred before the cast, so the
    separation of two beads carries a relative rounding error of ~6e-8 (float32 epsilon)
    x (chain extent / separation); measured 7e-7 relative (1.4e-6 largest component) on the
    1000-bead chain of benchmarks/scaling.py, 3e-6 at 4000, 1.2e-5 at 16000.
    """
    n = x.shape[0]
    c0 = x[:, 0].mean()
    c1 = x[:, 1].mean()
    c2 = x[:, 2].mean()
    xs = np.empty(n, np.float32)
    ys = np.empty(n, np.float32)
    zs = np.empty(n, np.float32)
    fx = np.empty(n, np.float32)
    fy = np.empty(n, np.float32)
    fz = np.empty(n, np.float32)
    for i in range(n):
        xs[i] = x[i, 0] - c0
        ys[i] = x[i, 1] - c1
        zs[i] = x[i, 2] - c2
        fx[i] = F[i, 0]
        fy[i] = F[i, 1]
        fz[i] = F[i, 2]
    ox, oy, oz = _sym_sums(xs, ys, zs, fx, fy, fz, _rpy_constants32(a), block)
    for i in range(n):
        out[i, 0] = ox[i]
        out[i, 1] = oy[i]
        out[i, 2] = oz[i]


SYMMETRIC_MIN_N = 256  # below it the gather loop wins (N = 61: 0.007 vs 0.012 ms)
SYMMETRIC_BLOCK = 2048


@nb.njit(cache=True, fastmath=True, error_model="numpy", parallel=True)
def _rpy_apply_parallel(x, a, F, out, nchunk):
    n = x.shape[0]
    xs, ys, zs, fx, fy, fz = _soa(x, F)
    ox, oy, oz = np.empty(n), np.empty(n), np.empty(n)
    for c in nb.prange(nchunk):
        _rows_serial(xs, ys, zs, a, fx, fy, fz, ox, oy, oz,
                     (c * n) // nchunk, ((c + 1) * n) // nchunk)
    _aos(ox, oy, oz, out)


def rpy_apply(x, a, F, out, threads=1):
    """``out = mu_hat F`` matrix-free, O(n^2) time, O(n) memory (x, F, out: (n, 3)).

    One compiled call (the structure-of-arrays copies are made inside, so the Python overhead
    stays ~1 us at N = 61). Serial: the gather loop below ``SYMMETRIC_MIN_N`` beads, the
    once-per-pair loop :func:`_rpy_apply_sym` above. ``threads > 1`` splits the rows over
    numba threads (the same pair sums per row; equal to rounding, not necessarily bit for
    bit).
    """
    if threads > 1 and x.shape[0] >= 256:
        _rpy_apply_parallel(x, float(a), F, out, 8 * threads)
    elif x.shape[0] >= SYMMETRIC_MIN_N:
        _rpy_apply_sym(x, float(a), F, out, SYMMETRIC_BLOCK)
    else:
        _rpy_apply_serial(x, float(a), F, out)


@nb.njit(cache=True)
def rpy_band_blocks(x, a, w, out):
    """``out[i, w + k] = mu_hat_{i, i+k}`` (3x3) for |k| <= w (zero past the chain ends).

    The near-field blocks a banded preconditioner assembles ``W`` from; ``w = 0`` is the
    self mobility alone.
    """
    n = x.shape[0]
    s = 1.0 / (6.0 * math.pi * a)
    out[:, :, :, :] = 0.0
    for i in range(n):
        for p in range(3):
            out[i, w, p, p] = s
        for k in range(1, w + 1):
            j = i + k
            if j >= n:
                break
            d0 = x[i, 0] - x[j, 0]
            d1 = x[i, 1] - x[j, 1]
            d2 = x[i, 2] - x[j, 2]
            r = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            f, g = _pair(r, a)
            u = (d0 / r, d1 / r, d2 / r) if r > 0.0 else (0.0, 0.0, 0.0)
            for p in range(3):
                for q in range(3):
                    v = g * u[p] * u[q] + (f if p == q else 0.0)
                    out[i, w + k, p, q] = v
                    out[j, w - k, q, p] = v


@nb.njit(cache=True)
def rpy_overlap_correction(x, a, pairs, F, out):
    """Add ``(overlap form - far form) F`` for the listed pairs (i < j, r < 2a) to ``out``.

    For a fast far-field evaluator (FMM) that applies the ``r >= 2a`` RPY form to every pair.
    """
    s = 1.0 / (6.0 * math.pi * a)
    for k in range(pairs.shape[0]):
        i = pairs[k, 0]
        j = pairs[k, 1]
        d0 = x[i, 0] - x[j, 0]
        d1 = x[i, 1] - x[j, 1]
        d2 = x[i, 2] - x[j, 2]
        r = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if r == 0.0 or r >= 2.0 * a:
            continue
        c = 1.0 / (8.0 * math.pi * r)
        q = a * a / (r * r)
        ff = c * (1.0 + 2.0 * q / 3.0)
        gf = c * (1.0 - 2.0 * q)
        fn = s * (1.0 - 9.0 * r / (32.0 * a))
        gn = s * (3.0 * r / (32.0 * a))
        df = fn - ff
        dg = (gn - gf) / (r * r)
        add_pair_product(out, F, i, j, df, dg, d0, d1, d2)
