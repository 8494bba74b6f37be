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

Pairs whose contour gap (from the end of one segment to the start of the other) is shorter
than the cut-off plus the longest rest bond are skipped: neighbouring bonds always lie within
the cut-off of each other on a smooth filament. On a uniform chain this skips
``j - i <= exclude = ceil(d_c / b) + 1``; on a chain with short bonds (a resolved hook) it
skips by contour length, not by bond count. :func:`self_contact_hessian` gives the pair
Hessians (central differences of the exact pair gradient) for the implicit integrators. :func:`count_crossings` counts the
segment pairs that pass through each other between saved frames of a run (the check that the
repulsion works; docs/model.md).

In the simulated system it is the interaction :class:`SelfContactInteraction`
(``contact.self_contact = true``).
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
def _pair_law(d, cut, sigma, eps, k2):
    """The pair energy ``U(d)`` (module docstring) and ``U'(d)/d``, for ``0 < d < cut``."""
    s6 = (sigma / d) ** 6
    U = 4.0 * eps * (s6 * s6 - s6) + eps - 0.5 * k2 * (d - cut) ** 2
    return U, (4.0 * eps * (-12.0 * s6 * s6 + 6.0 * s6) / d - k2 * (d - cut)) / d


@nb.njit(cache=True)
def self_contact_energy_grad(x, cut, sigma, eps, c2, first, grad, skip):
    """Energy of the segment-pair repulsion of the chain ``x`` (N, 3); adds ``dU/dx`` to
    ``grad``. Segment ``i`` meets segments ``j >= first[i]`` only (its contour neighbours are
    skipped), and none with ``skip[j]`` (the joins between the chains of several filaments
    laid end to end, which are no segments). Returns ``(energy, smallest segment distance
    among the pairs considered)``."""
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
        for j in range(first[i], n):
            if skip[j]:
                continue
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
            U, dU = _pair_law(d, cut, sigma, eps, k2)
            E += U
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
    """Repulsion between non-neighbouring segments of one filament, or of several laid end to
    end (``chains``), which then also repel each other (core units).

    Parameters
    ----------
    radius : float
        filament cross-section radius ``a`` [L].
    bond : float
        bond length ``b`` [L] of a uniform chain (sets the contour exclusion), or ignored when
        ``rest_lengths`` (N-1,) are given.
    range : float
        the repulsion starts ``range * a`` before the surfaces touch: cut-off ``a (2 + range)``.
    strength : float
        energy scale ``eps`` [A/L] (the body contact uses ``contact.strength / b``).
    c2 : float
        1: "wca-c2" (continuous force derivative at the cut-off, the default); 0: plain WCA.
    chains : sequence of int, optional
        the bead counts of several filaments whose beads ``x`` holds one after the other
        (``rest_lengths`` then holds their bonds only, one chain after the other): each
        keeps its own contour exclusion, every pair of segments on different chains is a
        contact pair, and the join from one chain's last bead to the next one's first is no
        segment.
    """

    def __init__(self, radius: float, bond: float, range: float = 1.0, strength: float = 1.0,
                 c2: float = 1.0, rest_lengths=None, chains=None):
        if not (radius > 0 and bond > 0 and range > 0 and strength > 0):
            raise ValueError("SelfContact: radius, bond, range and strength must be > 0")
        self.cut = radius * (2.0 + range)
        self.sigma = self.cut / 2.0 ** (1.0 / 6.0)
        self.eps = float(strength)
        self.c2 = float(c2)
        self.rest_lengths = None if rest_lengths is None else np.asarray(rest_lengths, float)
        # bonds whose contour distance is within the cut-off are neighbours, not contacts
        self.exclude = int(math.ceil(self.cut / bond)) + 1
        self._first_n = None
        self.chains = None if chains is None else [int(n) for n in chains]
        if self.chains is not None and (min(self.chains) < 2 or (
                self.rest_lengths is not None
                and len(self.rest_lengths) != sum(self.chains) - len(self.chains))):
            raise ValueError("SelfContact: chains need >= 2 beads each and rest_lengths one "
                             "entry per bond of every chain")

    def first(self, n_segments: int) -> np.ndarray:
        """``first[i]``: the first segment that segment ``i`` can touch (module docstring)."""
        if self._first_n is not None and self._first_n[0] == n_segments:
            return self._first_n[1]
        if self.chains is not None:
            return self._chains_first(n_segments)
        if self.rest_lengths is None:
            first = np.arange(n_segments, dtype=np.int64) + self.exclude + 1
        else:
            l0 = self.rest_lengths
            arc = np.concatenate([[0.0], np.cumsum(l0)])
            need = self.cut + l0.max() - 1e-9 * l0.max()
            # first j with arc[j] - arc[i + 1] >= need
            first = np.searchsorted(arc, arc[1:] + need, side="left").astype(np.int64)
        first = np.minimum(first, n_segments)
        self._first_n = (n_segments, first, np.zeros(n_segments, np.bool_))
        return first

    def skip(self, n_segments: int) -> np.ndarray:
        """``skip[j]``: segment ``j`` is the join between two chains (``chains``)."""
        self.first(n_segments)
        return self._first_n[2]

    def _chains_first(self, n_segments: int) -> np.ndarray:
        if n_segments != sum(self.chains) - 1:
            raise ValueError(f"SelfContact: {n_segments + 1} beads, chains of {self.chains}")
        first = np.empty(n_segments, np.int64)
        skip = np.zeros(n_segments, np.bool_)
        start = bond = 0  # first bead of the chain, its first bond among rest_lengths
        for n in self.chains:
            one = SelfContact.__new__(SelfContact)  # this chain alone, same law
            one.__dict__.update(self.__dict__)
            one.chains, one._first_n = None, None
            if self.rest_lengths is not None:
                one.rest_lengths = self.rest_lengths[bond:bond + n - 1]
            first[start:start + n - 1] = start + one.first(n - 1)
            if start + n - 1 < n_segments:  # the join to the next chain
                first[start + n - 1] = n_segments
                skip[start + n - 1] = True
            start, bond = start + n, bond + n - 1
        self._first_n = (n_segments, first, skip)
        return first

    @property
    def exclude(self) -> int:
        return self._exclude

    @exclude.setter
    def exclude(self, value: int):
        self._exclude = int(value)
        self._first_n = None

    def energy_grad(self, x: np.ndarray, grad: np.ndarray) -> tuple[float, float]:
        """``(energy, smallest distance)``; adds ``dU/dx`` to ``grad`` (N, 3)."""
        x = np.ascontiguousarray(x, float)
        n = len(x) - 1
        return self_contact_energy_grad(x, self.cut, self.sigma, self.eps, self.c2,
                                        self.first(n), grad, self.skip(n))

    def hessian_coo(self, x: np.ndarray):
        """``d^2 U / dx^2`` as COO triplets over bead coordinates ``3 i + c`` (active pairs only)."""
        x = np.ascontiguousarray(x, float)
        n = len(x) - 1
        return self_contact_hessian(x, self.cut, self.sigma, self.eps, self.c2,
                                    self.first(n), self.skip(n))


@nb.njit(cache=True)
def _pair_grad(P, cut, sigma, eps, k2, out):
    """Gradient (12,) of one pair's energy w.r.t. ``P`` = (x_i, x_i+1, x_j, x_j+1) (12,)."""
    s, t, dx, dy, dz = segment_closest(P[0:3], P[3:6], P[6:9], P[9:12])
    d = math.sqrt(dx * dx + dy * dy + dz * dz)
    out[:] = 0.0
    if d >= cut or d <= 0.0:
        return
    dU = _pair_law(d, cut, sigma, eps, k2)[1]
    w = (1.0 - s, s, -(1.0 - t), -t)
    for k in range(4):
        out[3 * k] = w[k] * dU * dx
        out[3 * k + 1] = w[k] * dU * dy
        out[3 * k + 2] = w[k] * dU * dz


@nb.njit(cache=True)
def self_contact_hessian(x, cut, sigma, eps, c2, first, skip):
    """Hessian triplets of the pairs within the cut-off: central differences (step
    ``1e-6 d_c``) of the exact pair gradient, 144 entries per active pair."""
    n = x.shape[0] - 1
    k2 = c2 * 72.0 * eps / (cut * cut)
    pairs_i = []
    pairs_j = []
    for i in range(n):
        for j in range(first[i], n):
            if skip[j]:
                continue
            s, t, dx, dy, dz = segment_closest(x[i], x[i + 1], x[j], x[j + 1])
            if dx * dx + dy * dy + dz * dz < cut * cut:
                pairs_i.append(i)
                pairs_j.append(j)
    m = len(pairs_i)
    rows = np.empty(144 * m, np.int64)
    cols = np.empty(144 * m, np.int64)
    vals = np.empty(144 * m)
    P = np.empty(12)
    gp = np.empty(12)
    gm = np.empty(12)
    h = 1e-6 * cut
    q = 0
    for p in range(m):
        i = pairs_i[p]
        j = pairs_j[p]
        beads = (i, i + 1, j, j + 1)
        for k in range(4):
            for c in range(3):
                P[3 * k + c] = x[beads[k], c]
        for col in range(12):
            v = P[col]
            P[col] = v + h
            _pair_grad(P, cut, sigma, eps, k2, gp)
            P[col] = v - h
            _pair_grad(P, cut, sigma, eps, k2, gm)
            P[col] = v
            for row in range(12):
                rows[q] = 3 * beads[row // 3] + row % 3
                cols[q] = 3 * beads[col // 3] + col % 3
                vals[q] = (gp[row] - gm[row]) / (2.0 * h)
                q += 1
    return rows, cols, vals


class SelfContactInteraction:
    """:class:`SelfContact` as an interaction of the system (:mod:`flagwrap.interactions.base`)."""

    name = "self_contact"
    nonlocal_hessian = True  # pairs far apart along the chain: not in banded solvers' W
    rotation_invariant = True  # depends on distances only (the rotating frame may use it)

    def __init__(self, contact: SelfContact):
        self.contact = contact
        self.min_distance = np.inf

    def energy_grad(self, x, theta, grad_x, grad_theta) -> float:
        E, dmin = self.contact.energy_grad(x, grad_x)
        self.min_distance = dmin
        return E

    def hessian_coo(self, x, theta):
        return self.contact.hessian_coo(x)


def max_self_range(config) -> float:
    """The largest ``contact.self_range`` [a] that leaves the stress-free filament (with its
    joint) out of contact with itself; ``inf`` for a shape with no non-neighbouring segments
    close enough to matter."""
    from flagwrap.elasticity.rod import initial_frames  # noqa: F401  (light import)
    from flagwrap.geometry.helix import filament_positions
    from flagwrap.joints import make_joint

    fil = config.filament
    L = fil.length
    x0 = filament_positions(fil, config.clamp) / L
    _, x, _ = make_joint(config, x0, np.zeros(len(x0) - 1))
    x = np.ascontiguousarray(x)
    l0 = np.linalg.norm(np.diff(x, axis=0), axis=1)
    a = fil.cross_section_radius / L

    def touches(r):
        sc = SelfContact(a, fil.bond_length / L, range=r, rest_lengths=l0)
        return sc.energy_grad(x, np.zeros_like(x))[0] > 0.0

    if touches(1e-9):
        return 0.0
    # grow the range until the stress-free shape touches itself, or until the contour
    # exclusion (which grows with the cut-off) leaves no pair to touch
    lo, hi = 0.0, 0.01
    while not touches(hi):
        sc = SelfContact(a, fil.bond_length / L, range=hi, rest_lengths=l0)
        if sc.first(len(x) - 1)[0] >= len(x) - 1:
            return math.inf
        lo, hi = hi, 2.0 * hi
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        if touches(mid):
            hi = mid
        else:
            lo = mid
    return lo


@nb.njit(cache=True)
def _oriented(p0, p1, q0, q1):
    """(q0 - p0) . ((p1 - p0) x (q1 - q0)): changes sign when the two lines pass through each other."""
    ax, ay, az = p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]
    bx, by, bz = q1[0] - q0[0], q1[1] - q0[1], q1[2] - q0[2]
    cx, cy, cz = q0[0] - p0[0], q0[1] - p0[1], q0[2] - p0[2]
    return cx * (ay * bz - az * by) + cy * (az * bx - ax * bz) + cz * (ax * by - ay * bx)


@nb.njit(cache=True)
def _crossings(X, exclude, near, chain):
    n = X.shape[1] - 1
    count = 0
    for k in range(X.shape[0] - 1):
        A = X[k]
        B = X[k + 1]
        for i in range(n):
            if chain[i] < 0:
                continue
            for j in range(i + 1, n):
                if chain[j] < 0 or (chain[j] == chain[i] and j <= i + exclude):
                    continue
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


def count_crossings(positions: np.ndarray, exclude: int = 2, near: float | None = None,
                    chains=None) -> int:
    """Number of times two non-neighbouring segments pass through each other between
    consecutive frames of ``positions`` (F, N, 3): the oriented volume of the two segments
    changes sign while both are within ``near`` (default: one mean bond length) with their
    closest points inside both segments. Frames must be close enough that a segment moves
    less than ``near`` between them (a run's saved frames are: 0.05 turns).

    ``chains``: the bead counts of several filaments laid one after the other (a run of
    several flagella); every pair of segments on different filaments counts, the joins
    between them are no segments."""
    X = np.ascontiguousarray(positions, float)
    n = X.shape[1] - 1
    chain = np.zeros(n, np.int64)
    if chains is not None:
        if sum(chains) != X.shape[1]:
            raise ValueError(f"chains {list(chains)} do not add up to {X.shape[1]} beads")
        start = 0
        for c, m in enumerate(chains):
            chain[start:start + m - 1] = c
            if start + m - 1 < n:
                chain[start + m - 1] = -1  # the join to the next filament
            start += m
    if near is None:
        d = np.linalg.norm(np.diff(X[0], axis=0), axis=1)
        near = float(d[chain >= 0].mean())
    return int(_crossings(X, int(exclude), float(near), chain))
