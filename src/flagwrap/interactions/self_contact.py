"""Filament self-contact: a short-range repulsion between non-neighbouring segments.

The distance is between *segments* (the bonds ``x_i x_{i+1}``), not beads, so two parts of a
folded filament cannot slip through each other between beads however coarse the chain. For
segments ``i`` and ``j`` with closest points ``p = x_i + s (x_{i+1} - x_i)`` and
``q = x_j + t (x_{j+1} - x_j)`` (``s, t`` in [0, 1]; Ericson, *Real-Time Collision Detection*,
2005, section 5.1.9), ``d = |p - q|`` and the pair energy is the body contact's law
(:func:`flagwrap.body._kernels.wca_energy_grad`, "wca-c2" with ``c2 = 1``)

    U(d) = 4 eps [(sigma/d)^12 - (sigma/d)^6] + eps - c2 k (d - d_c)^2 / 2,   d < d_c,

with the cut-off ``d_c = a (2 + range)``: the filament surfaces touch at ``d = 2a`` and the
repulsion starts ``range a`` before. By the envelope theorem (the closest points minimise the
distance) ``dd/dx_i = (1 - s) n``, ``dd/dx_{i+1} = s n``, ``dd/dx_j = -(1 - t) n``,
``dd/dx_{j+1} = -t n`` with ``n = (p - q)/d``: the exact gradient wherever the closest points
are unique (tests/unit/test_self_contact.py checks it against finite differences).

Pairs closer than ``exclude`` bonds along the contour are skipped: neighbouring bonds always
lie within the cut-off of each other on a smooth filament. :func:`count_crossings` counts the
segment pairs that pass through each other between saved frames of a run (the check that the
repulsion works; docs/model.md).

Not yet part of the simulated system: issue 15's composable system adds it as an interaction.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np


@nb.njit(cache=True)
def segment_closest(p0, p1, q0, q1):
    """Closest points of segments ``p0 p1`` and ``q0 q1``: ``(s, t, dx, dy, dz)`` with the
    parameters in [0, 1] and ``p(s) - q(t)`` (Ericson 2005, 5.1.9, degenerate cases included)."""
    d1x, d1y, d1z = p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]
    d2x, d2y, d2z = q1[0] - q0[0], q1[1] - q0[1], q1[2] - q0[2]
    rx, ry, rz = p0[0] - q0[0], p0[1] - q0[1], p0[2] - q0[2]
    a = d1x * d1x + d1y * d1y + d1z * d1z
    e = d2x * d2x + d2y * d2y + d2z * d2z
    f = d2x * rx + d2y * ry + d2z * rz
    eps = 1e-300
    if a <= eps and e <= eps:
        s = 0.0
        t = 0.0
    elif a <= eps:
        s = 0.0
        t = min(max(f / e, 0.0), 1.0)
    else:
        c = d1x * rx + d1y * ry + d1z * rz
        if e <= eps:
            t = 0.0
            s = min(max(-c / a, 0.0), 1.0)
        else:
            b = d1x * d2x + d1y * d2y + d1z * d2z
            den = a * e - b * b
            s = min(max((b * f - c * e) / den, 0.0), 1.0) if den > 1e-14 * a * e else 0.0
            t = (b * s + f) / e
            if t < 0.0:
                t = 0.0
                s = min(max(-c / a, 0.0), 1.0)
            elif t > 1.0:
                t = 1.0
                s = min(max((b - c) / a, 0.0), 1.0)
    dx = rx + s * d1x - t * d2x
    dy = ry + s * d1y - t * d2y
    dz = rz + s * d1z - t * d2z
    return s, t, dx, dy, dz


@nb.njit(cache=True)
def self_contact_energy_grad(x, cut, sigma, eps, c2, exclude, grad):
    """Energy of the segment-pair repulsion of the chain ``x`` (N, 3); adds ``dU/dx`` to
    ``grad``. Pairs ``(i, j)`` with ``j - i <= exclude`` are skipped. Returns
    ``(energy, smallest segment distance among the pairs considered)``."""
    n = x.shape[0] - 1
    k2 = c2 * 72.0 * eps / (cut * cut)
    E = 0.0
    dmin = np.inf
    for i in range(n):
        # bounding spheres: centre, half length; skip pairs that cannot be within cut
        cix = 0.5 * (x[i, 0] + x[i + 1, 0])
        ciy = 0.5 * (x[i, 1] + x[i + 1, 1])
        ciz = 0.5 * (x[i, 2] + x[i + 1, 2])
        hi = 0.5 * math.sqrt((x[i + 1, 0] - x[i, 0]) ** 2 + (x[i + 1, 1] - x[i, 1]) ** 2
                             + (x[i + 1, 2] - x[i, 2]) ** 2)
        for j in range(i + exclude + 1, n):
            cjx = 0.5 * (x[j, 0] + x[j + 1, 0])
            cjy = 0.5 * (x[j, 1] + x[j + 1, 1])
            cjz = 0.5 * (x[j, 2] + x[j + 1, 2])
            hj = 0.5 * math.sqrt((x[j + 1, 0] - x[j, 0]) ** 2 + (x[j + 1, 1] - x[j, 1]) ** 2
                                 + (x[j + 1, 2] - x[j, 2]) ** 2)
            cc = math.sqrt((cix - cjx) ** 2 + (ciy - cjy) ** 2 + (ciz - cjz) ** 2)
            if cc - hi - hj >= cut and cc - hi - hj >= dmin:
                continue
            s, t, dx, dy, dz = segment_closest(x[i], x[i + 1], x[j], x[j + 1])
            d = math.sqrt(dx * dx + dy * dy + dz * dz)
            if d < dmin:
                dmin = d
            if d >= cut or d <= 0.0:
                continue
            s6 = (sigma / d) ** 6
            E += 4.0 * eps * (s6 * s6 - s6) + eps - 0.5 * k2 * (d - cut) ** 2
            dU = (4.0 * eps * (-12.0 * s6 * s6 + 6.0 * s6) / d - k2 * (d - cut)) / d
            gx, gy, gz = dU * dx, dU * dy, dU * dz
            grad[i, 0] += (1.0 - s) * gx
            grad[i, 1] += (1.0 - s) * gy
            grad[i, 2] += (1.0 - s) * gz
            grad[i + 1, 0] += s * gx
            grad[i + 1, 1] += s * gy
            grad[i + 1, 2] += s * gz
            grad[j, 0] -= (1.0 - t) * gx
            grad[j, 1] -= (1.0 - t) * gy
            grad[j, 2] -= (1.0 - t) * gz
            grad[j + 1, 0] -= t * gx
            grad[j + 1, 1] -= t * gy
            grad[j + 1, 2] -= t * gz
    return E, dmin


class SelfContact:
    """Repulsion between non-neighbouring segments of one filament (core units).

    Parameters
    ----------
    radius : float
        filament cross-section radius ``a`` [L].
    bond : float
        bond length ``b`` [L] (sets the contour exclusion).
    range : float
        the repulsion starts ``range * a`` before the surfaces touch: cut-off ``a (2 + range)``.
    strength : float
        energy scale ``eps`` [A/L] (the body contact uses ``contact.strength / b``).
    c2 : float
        1: "wca-c2" (continuous force derivative at the cut-off, the default); 0: plain WCA.
    """

    def __init__(self, radius: float, bond: float, range: float = 1.0, strength: float = 1.0,
                 c2: float = 1.0):
        if not (radius > 0 and bond > 0 and range > 0 and strength > 0):
            raise ValueError("SelfContact: radius, bond, range and strength must be > 0")
        self.cut = radius * (2.0 + range)
        self.sigma = self.cut / 2.0 ** (1.0 / 6.0)
        self.eps = float(strength)
        self.c2 = float(c2)
        # bonds whose contour distance is within the cut-off are neighbours, not contacts
        self.exclude = int(math.ceil(self.cut / bond)) + 1

    def energy_grad(self, x: np.ndarray, grad: np.ndarray) -> tuple[float, float]:
        """``(energy, smallest distance)``; adds ``dU/dx`` to ``grad`` (N, 3)."""
        return self_contact_energy_grad(np.ascontiguousarray(x, float), self.cut, self.sigma,
                                        self.eps, self.c2, self.exclude, grad)


@nb.njit(cache=True)
def _oriented(p0, p1, q0, q1):
    """(q0 - p0) . ((p1 - p0) x (q1 - q0)): changes sign when the two lines pass through each other."""
    ax, ay, az = p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]
    bx, by, bz = q1[0] - q0[0], q1[1] - q0[1], q1[2] - q0[2]
    cx, cy, cz = q0[0] - p0[0], q0[1] - p0[1], q0[2] - p0[2]
    return cx * (ay * bz - az * by) + cy * (az * bx - ax * bz) + cz * (ax * by - ay * bx)


@nb.njit(cache=True)
def _crossings(X, exclude, near):
    n = X.shape[1] - 1
    count = 0
    for k in range(X.shape[0] - 1):
        A = X[k]
        B = X[k + 1]
        for i in range(n):
            for j in range(i + exclude + 1, n):
                va = _oriented(A[i], A[i + 1], A[j], A[j + 1])
                vb = _oriented(B[i], B[i + 1], B[j], B[j + 1])
                if (va > 0.0) == (vb > 0.0):  # no sign change (an exact 0 counts as negative)
                    continue
                # a sign change also happens when far-apart segments turn parallel: count it
                # only where the segments were close and the closest points inside both
                sa, ta, ax, ay, az = segment_closest(A[i], A[i + 1], A[j], A[j + 1])
                sb, tb, bx, by, bz = segment_closest(B[i], B[i + 1], B[j], B[j + 1])
                if (math.sqrt(ax * ax + ay * ay + az * az) < near
                        and math.sqrt(bx * bx + by * by + bz * bz) < near
                        and 0.0 < sa < 1.0 and 0.0 < ta < 1.0 and 0.0 < sb < 1.0 and 0.0 < tb < 1.0):
                    count += 1
    return count


def count_crossings(positions: np.ndarray, exclude: int = 2, near: float | None = None) -> int:
    """Number of times two non-neighbouring segments pass through each other between
    consecutive frames of ``positions`` (F, N, 3): the oriented volume of the two segments
    changes sign while both are within ``near`` (default: one mean bond length) with their
    closest points inside both segments. Frames must be close enough that a segment moves
    less than ``near`` between them (a run's saved frames are: 0.05 turns)."""
    X = np.ascontiguousarray(positions, float)
    if near is None:
        near = float(np.linalg.norm(np.diff(X[0], axis=0), axis=1).mean())
    return int(_crossings(X, int(exclude), float(near)))
