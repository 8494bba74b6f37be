"""Numba kernels: distance to the cell body (a capped cylinder or a spheroid) and the WCA
repulsion.

Body axis = +z; the hemispherical cap of radius ``Rc`` is centred at ``(0, 0, Rc)`` so its
lowest point is the origin (the clamp); the cylinder continues up to ``z = Rc + H``.
"""

from __future__ import annotations

import math

import numba as nb


@nb.njit(cache=True, inline="always")
def surface_distance(px, py, pz, Rc, H):
    """Signed distance to the body surface (negative inside) and its unit gradient."""
    if pz < Rc:
        dx, dy, dz = px, py, pz - Rc
        r = math.sqrt(dx * dx + dy * dy + dz * dz)
        if r == 0.0:
            return -Rc, 0.0, 0.0, -1.0
        return r - Rc, dx / r, dy / r, dz / r
    rho = math.sqrt(px * px + py * py)
    ztop = Rc + H
    if pz <= ztop:
        if rho == 0.0:
            return -Rc, 1.0, 0.0, 0.0
        d_side = rho - Rc
        if d_side < 0.0 and (ztop - pz) < -d_side:  # inside, nearer the top face
            return pz - ztop, 0.0, 0.0, 1.0
        return d_side, px / rho, py / rho, 0.0
    # above the top face
    if rho <= Rc:
        return pz - ztop, 0.0, 0.0, 1.0
    dr = rho - Rc
    dz = pz - ztop
    d = math.sqrt(dr * dr + dz * dz)
    return d, dr / d * px / rho, dr / d * py / rho, dz / d


@nb.njit(cache=True, inline="always")
def spheroid_distance(px, py, pz, a, c):
    """Signed distance to the spheroid of equatorial semi-axis ``a`` and axial ``c``, centred
    at ``(0, 0, c)`` (lowest point at the origin), to first order in the distance, and its
    gradient: ``d = (s - 1) / |grad s|``, ``s = sqrt(rho^2/a^2 + (z - c)^2/c^2)`` (Taubin's
    distance of the level set ``s = 1``; exact for a sphere, zero on the surface, error
    O(d^2 / R) beside it, where the contact law acts). The gradient is d's own, so the forces
    stay the exact gradient of the contact energy."""
    w = pz - c
    ia2, ic2 = 1.0 / (a * a), 1.0 / (c * c)
    s2 = (px * px + py * py) * ia2 + w * w * ic2
    if s2 == 0.0:
        return -min(a, c), 0.0, 0.0, -1.0
    s = math.sqrt(s2)
    q = math.sqrt((px * px + py * py) * ia2 * ia2 + w * w * ic2 * ic2)
    g = s2 - s
    d = g / q
    # grad d = (2 s - 1) grad s / q - g grad q / q^2, grad s = (x/a^2, y/a^2, w/c^2) / s,
    # grad q = (x/a^4, y/a^4, w/c^4) / q
    f1 = (2.0 * s - 1.0) / (s * q)
    f2 = g / (q * q * q)
    return (d, px * (f1 * ia2 - f2 * ia2 * ia2), py * (f1 * ia2 - f2 * ia2 * ia2),
            w * (f1 * ic2 - f2 * ic2 * ic2))


@nb.njit(cache=True, inline="always")
def body_distance(px, py, pz, Rc, H, shape):
    """``shape`` 0: the capped cylinder (:func:`surface_distance`); 1: the spheroid of
    equatorial radius ``Rc`` and length ``Rc + H`` (:func:`spheroid_distance`)."""
    if shape == 1:
        return spheroid_distance(px, py, pz, Rc, 0.5 * (Rc + H))
    return surface_distance(px, py, pz, Rc, H)


@nb.njit(cache=True)
def wca_energy_grad(x, first, Rc, H, sigma, eps, c2, grad, dist, shape=0):
    """WCA repulsion of beads ``first..`` from the body; adds dU/dx to ``grad``.

    ``U(d) = 4 eps [(sigma/d)^12 - (sigma/d)^6] + eps - c2 k (d - d_c)^2 / 2`` for
    ``d < d_c = 2^(1/6) sigma``, 0 beyond, with ``k = 72 eps / d_c^2`` the WCA stiffness at
    the cut-off. ``c2 = 0`` is the plain WCA law, whose stiffness jumps from ``k`` to 0 at
    the cut-off; ``c2 = 1`` subtracts that curvature so the force has a continuous derivative
    there (near the cut-off U ~ (d_c - d)^3; still repulsive and monotone on (0, d_c), still
    diverging as d -> 0). ``dist`` (N,) receives each bead's signed distance. Returns the
    energy; a bead inside (d <= 0) gets zero force here and is caught by the guards.
    """
    cut = 2.0 ** (1.0 / 6.0) * sigma
    k2 = c2 * 72.0 * eps / (cut * cut)
    E = 0.0
    for i in range(x.shape[0]):
        d, gx, gy, gz = body_distance(x[i, 0], x[i, 1], x[i, 2], Rc, H, shape)
        dist[i] = d
        if i < first or d >= cut or d <= 0.0:
            continue
        s6 = (sigma / d) ** 6
        E += 4.0 * eps * (s6 * s6 - s6) + eps - 0.5 * k2 * (d - cut) ** 2
        dU = 4.0 * eps * (-12.0 * s6 * s6 + 6.0 * s6) / d - k2 * (d - cut)
        grad[i, 0] += dU * gx
        grad[i, 1] += dU * gy
        grad[i, 2] += dU * gz
    return E


@nb.njit(cache=True)
def distances(x, Rc, H, shape, d, n):
    """Each point's signed distance ``d`` (n,) to the body ``shape`` (:func:`body_distance`)
    and its gradient ``n`` (n, 3)."""
    for i in range(x.shape[0]):
        d[i], n[i, 0], n[i, 1], n[i, 2] = body_distance(x[i, 0], x[i, 1], x[i, 2], Rc, H, shape)


@nb.njit(cache=True)
def wca_law(d, sigma, eps, c2, energy, dU, d2U):
    """The body contact's law of :func:`wca_energy_grad` on given distances: ``energy``,
    ``dU/dd`` and ``d^2U/dd^2`` (zero beyond the cut-off and for ``d <= 0``)."""
    cut = 2.0 ** (1.0 / 6.0) * sigma
    k2 = c2 * 72.0 * eps / (cut * cut)
    for i in range(d.shape[0]):
        di = d[i]
        if di >= cut or di <= 0.0:
            energy[i] = dU[i] = d2U[i] = 0.0
            continue
        s6 = (sigma / di) ** 6
        energy[i] = 4.0 * eps * (s6 * s6 - s6) + eps - 0.5 * k2 * (di - cut) ** 2
        dU[i] = 4.0 * eps * (-12.0 * s6 * s6 + 6.0 * s6) / di - k2 * (di - cut)
        d2U[i] = 4.0 * eps * (156.0 * s6 * s6 - 42.0 * s6) / (di * di) - k2
