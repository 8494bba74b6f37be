"""Fused numba kernels of :class:`flagwrap.system.rod_system.RodSystem` (one call per force evaluation).

``generalized_forces`` unpacks the state vector (clamp + free beads/bonds), evaluates the
elastic energy and gradient, the body repulsion and gravity, and packs ``G = -dU/dy``;
``fd_jacobian`` builds ``dG/dy`` by coloured one-sided differences. They exist only to remove
Python overhead from the hot loop; the physics lives in the kernels they call.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from flagwrap.body._kernels import wca_energy_grad
from flagwrap.elasticity._kernels import energy_grad


@nb.njit(cache=True)
def unpack(y, nc, ec, x_ref, axis, origin, theta_ref, twist_rate, x, theta):
    """The joint's beads rotated by the motor angle ``phi = y[-1]`` about ``axis`` through
    ``origin`` (``x_ref`` relative to ``origin``), then the free beads and bonds from ``y``."""
    N = x.shape[0]
    phi = y[y.shape[0] - 1]
    c = math.cos(phi)
    s = math.sin(phi)
    for i in range(nc):  # Rodrigues rotation of the clamped beads about the motor axis
        v0, v1, v2 = x_ref[i, 0], x_ref[i, 1], x_ref[i, 2]
        kx = axis[1] * v2 - axis[2] * v1
        ky = axis[2] * v0 - axis[0] * v2
        kz = axis[0] * v1 - axis[1] * v0
        kv = axis[0] * v0 + axis[1] * v1 + axis[2] * v2
        x[i, 0] = origin[0] + (c * v0 + s * kx + (1 - c) * kv * axis[0])
        x[i, 1] = origin[1] + (c * v1 + s * ky + (1 - c) * kv * axis[1])
        x[i, 2] = origin[2] + (c * v2 + s * kz + (1 - c) * kv * axis[2])
    k = 0
    for i in range(nc, N):
        x[i, 0] = y[k]
        x[i, 1] = y[k + 1]
        x[i, 2] = y[k + 2]
        k += 3
    for j in range(ec):
        theta[j] = theta_ref[j] + twist_rate * phi
    for j in range(ec, N - 1):
        theta[j] = y[k]
        k += 1


@nb.njit(cache=True)
def generalized_forces(y, nc, ec, x_ref, axis, origin, theta_ref, twist_rate,
                       base_t, base_d1, base_rt, l0, cbend, ctwist, angle_law, kbar, mbar, ks,
                       has_body, Rc, H, sigma, eps, c2, gravity,
                       G, x, theta, gx, gth, d1_out, rt_out, dist, shape=0):
    """Fill ``G`` (ny,) and the work arrays; return (elastic energy, contact energy)."""
    N = x.shape[0]
    unpack(y, nc, ec, x_ref, axis, origin, theta_ref, twist_rate, x, theta)
    E = energy_grad(x, theta, base_t, base_d1, base_rt, l0, cbend, ctwist, angle_law, kbar, mbar, ks,
                    gx, gth, d1_out, rt_out)
    Ec = 0.0
    if has_body:
        Ec = wca_energy_grad(x, nc, Rc, H, sigma, eps, c2, gx, dist, shape)
    else:
        for i in range(N):
            dist[i] = np.inf
    k = 0
    for i in range(nc, N):
        for m in range(3):
            G[k] = -(gx[i, m] - gravity[i, m])
            k += 1
    for i in range(N):
        for m in range(3):
            gx[i, m] -= gravity[i, m]
    for j in range(ec, N - 1):
        G[k] = -gth[j]
        k += 1
    G[k] = 0.0
    return E, Ec


@nb.njit(cache=True)
def fd_jacobian_coo(y, G0, delta, g_ptr, g_cols, e_ptr, e_rows, e_cols, N,
                    nc, ec, x_ref, axis, origin, theta_ref, twist_rate,
                    base_t, base_d1, base_rt, l0, cbend, ctwist, angle_law, kbar, mbar, ks,
                    has_body, Rc, H, sigma, eps, c2, gravity, shape=0):
    """``J = dG/dy`` as COO triplets (duplicates to be summed), O(N) time and memory.

    Analytic stretching Hessian + coloured differences of the rest. The stretching springs are
    ~1000x stiffer than bending; a finite-difference error of relative size ``delta/b`` in
    their block would be an O(1) error in ``W = I - gamma h Mob J`` and spoil the W-method's
    error constant, so their exact Hessian ``k_s [t t + (1 - l0/l)(I - t t)]`` is assembled
    directly and only bending, twist and contact (``ks = 0``) are differenced. Group ``g``
    perturbs columns ``g_cols[g_ptr[g]:g_ptr[g+1]]`` together and fills the (row, col) pairs
    ``e_rows/e_cols[e_ptr[g]:e_ptr[g+1]]``; the motor-angle column is differenced apart.
    """
    ny = y.shape[0]
    x = np.empty((N, 3))
    theta = np.empty(N - 1)
    gx = np.empty((N, 3))
    gth = np.empty(N - 1)
    d1 = np.empty((N - 1, 3))
    rt = np.empty(N)
    dist = np.empty(N)
    G = np.empty(ny)
    Gs = np.empty(ny)
    yp = y.copy()
    n_e = e_rows.shape[0]
    n_tot = n_e + 36 * (N - 1) + ny
    rows = np.empty(n_tot, np.int64)
    cols = np.empty(n_tot, np.int64)
    vals = np.empty(n_tot)
    generalized_forces(y, nc, ec, x_ref, axis, origin, theta_ref, twist_rate, base_t, base_d1,
                       base_rt, l0, cbend, ctwist, angle_law, kbar, mbar, 0.0, has_body, Rc, H, sigma,
                       eps, c2, gravity, Gs, x, theta, gx, gth, d1, rt, dist, shape)
    n_groups = g_ptr.shape[0] - 1
    for g in range(n_groups):
        for q in range(g_ptr[g], g_ptr[g + 1]):
            yp[g_cols[q]] += delta
        generalized_forces(yp, nc, ec, x_ref, axis, origin, theta_ref, twist_rate, base_t, base_d1,
                           base_rt, l0, cbend, ctwist, angle_law, kbar, mbar, 0.0, has_body, Rc, H, sigma,
                           eps, c2, gravity, G, x, theta, gx, gth, d1, rt, dist, shape)
        for q in range(e_ptr[g], e_ptr[g + 1]):
            r = e_rows[q]
            rows[q] = r
            cols[q] = e_cols[q]
            vals[q] = (G[r] - Gs[r]) / delta
        for q in range(g_ptr[g], g_ptr[g + 1]):
            yp[g_cols[q]] = y[g_cols[q]]
    k = n_e
    # exact stretching Hessian on the free beads (J = -Hessian)
    unpack(y, nc, ec, x_ref, axis, origin, theta_ref, twist_rate, x, theta)
    for j in range(N - 1):
        e0 = x[j + 1, 0] - x[j, 0]
        e1 = x[j + 1, 1] - x[j, 1]
        e2 = x[j + 1, 2] - x[j, 2]
        ln = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        t = (e0 / ln, e1 / ln, e2 / ln)
        c = 1.0 - l0[j] / ln
        for a_ in range(3):
            for b_ in range(3):
                K = ks * (t[a_] * t[b_] + c * ((1.0 if a_ == b_ else 0.0) - t[a_] * t[b_]))
                for p_ in range(2):
                    ip = j + p_
                    if ip < nc:
                        continue
                    for q_ in range(2):
                        iq = j + q_
                        if iq < nc:
                            continue
                        sgn = 1.0 if p_ == q_ else -1.0
                        rows[k] = 3 * (ip - nc) + a_
                        cols[k] = 3 * (iq - nc) + b_
                        vals[k] = -sgn * K
                        k += 1
    yp[ny - 1] += delta
    generalized_forces(yp, nc, ec, x_ref, axis, origin, theta_ref, twist_rate, base_t, base_d1,
                       base_rt, l0, cbend, ctwist, angle_law, kbar, mbar, ks, has_body, Rc, H, sigma,
                       eps, c2, gravity, G, x, theta, gx, gth, d1, rt, dist, shape)
    for r in range(ny):
        v = (G[r] - G0[r]) / delta
        if v != 0.0:
            rows[k] = r
            cols[k] = ny - 1
            vals[k] = v
            k += 1
    return rows[:k], cols[:k], vals[:k]


@nb.njit(cache=True)
def unit_tangents(x, t):
    """``t[j] = (x[j+1] - x[j]) / |x[j+1] - x[j]|`` (the next base's tangents)."""
    for j in range(x.shape[0] - 1):
        e0 = x[j + 1, 0] - x[j, 0]
        e1 = x[j + 1, 1] - x[j, 1]
        e2 = x[j + 1, 2] - x[j, 2]
        inv = 1.0 / math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        t[j, 0] = e0 * inv
        t[j, 1] = e1 * inv
        t[j, 2] = e2 * inv


@nb.njit(cache=True)
def band_from_triplets(rows, cols, vals, Mb, wd, mt, gamma_h, inv, kl, ku, n, ab, w):
    """LAPACK band storage of ``W' = I - gamma h Mob_near J`` (beads and twists, in the
    reverse-Cuthill-McKee order ``inv``) and the motor-angle columns ``w`` (n, n_motors) (see
    :class:`~flagwrap.integrators.linear.BandedW`).

    ``Mob_near``: translational 3x3 blocks ``Mb[i, wd + k] = Mob_{i, i+k}`` for |k| <= wd
    (``wd = 0``: the local mobility) and the twist diagonal ``mt``. Each triplet ``J[r, c] = v``
    adds ``-gamma h Mob[:, r] v`` to column ``c``; ``ab`` (2 kl + ku + 1, n), Fortran order,
    is zeroed here, ``ab[kl + ku + i - j, j] = W'[i, j]``. A triplet outside the band (an
    interaction whose pattern was not in the cached band structure) is left out: ``W`` is then
    approximate, which the W-methods tolerate, instead of a write out of bounds.
    """
    nb3 = Mb.shape[0] * 3
    nbd = Mb.shape[0]
    top = 2 * kl + ku
    ab[:, :] = 0.0
    w[:] = 0.0
    for q in range(rows.shape[0]):
        r = rows[q]
        if r >= n:
            continue
        c = cols[q]
        v = -gamma_h * vals[q]
        if r < nb3:
            p = r // 3
            k = r - 3 * p
            for dp in range(-wd, wd + 1):
                ib = p + dp
                if ib < 0 or ib >= nbd:
                    continue
                for m in range(3):
                    i = 3 * ib + m
                    val = Mb[ib, wd - dp, m, k] * v
                    if c >= n:
                        w[i, c - n] += val
                    else:
                        off = kl + ku + inv[i] - inv[c]
                        if kl <= off <= top:  # a term outside the band is left out of W
                            ab[off, inv[c]] += val
        else:
            val = mt[r - nb3] * v
            if c >= n:
                w[r, c - n] += val
            else:
                off = kl + ku + inv[r] - inv[c]
                if kl <= off <= top:
                    ab[off, inv[c]] += val
    for j in range(n):
        ab[kl + ku, j] += 1.0


@nb.njit(cache=True)
def scatter_dense(rows, cols, vals, J):
    J[:, :] = 0.0
    for q in range(rows.shape[0]):
        J[rows[q], cols[q]] += vals[q]


@nb.njit(cache=True)
def w_transpose_dense(rows, cols, vals, Mxx, mt, gamma_h, WT):
    """``WT = (I - gamma h Mob J)^T`` straight from the Jacobian triplets.

    ``Mob = blockdiag(Mxx, diag(mt), 0)`` (translations, twists, motor angle). Each triplet
    ``J[r, c] = v`` adds ``-gamma h Mob[:, r] v`` to column ``c`` of W, i.e. to row ``c`` of
    ``W^T``, a contiguous write (``Mxx`` is symmetric, so its row ``r`` is its column).
    O(nnz(J) * 3 nb) instead of the dense product's O(ny^3). The free swimmer's dense
    symmetric ``A`` over all its unknowns is the case ``Mxx = A``, ``mt`` empty
    (:class:`~flagwrap.system.swimmer.SwimmerW`).
    """
    n3 = Mxx.shape[0]
    ne = mt.shape[0]
    ny = WT.shape[0]
    WT[:, :] = 0.0
    for q in range(rows.shape[0]):
        r = rows[q]
        c = cols[q]
        v = -gamma_h * vals[q]
        if r < n3:
            for i in range(n3):
                WT[c, i] += Mxx[r, i] * v
        elif r < n3 + ne:
            WT[c, r] += mt[r - n3] * v
    for i in range(ny):
        WT[i, i] += 1.0


@nb.njit(cache=True)
def left_product_coo(P, rows, cols, vals, out):
    """``out = P J`` for ``J`` given by its triplets (duplicates add): O(nnz(J) rows(P)),
    where a dense ``J`` would make it O(rows(P) n^2)."""
    out[:, :] = 0.0
    for q in range(rows.shape[0]):
        r = rows[q]
        c = cols[q]
        v = vals[q]
        for i in range(P.shape[0]):
            out[i, c] += P[i, r] * v
    return out
