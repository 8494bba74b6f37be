"""The stress-free helix hanging from the clamp.

Layout (body axis = z, the cell body above z = 0, the clamp at the lowest point of the cap,
the origin): bead 0 sits at the clamp and the first bond points straight down along the body
axis (the paper's "vertically clamped" driving end, Discussion). From bead 1 on, the filament
is a uniform helix of radius ``R`` and pitch ``P`` whose axis is parallel to the body axis and
passes at distance ``R`` from it, so that the helix starts on the body axis where the clamped
bond ends. The kink between the vertical bond and the helix (angle ``psi``) is part of the
stress-free shape, so the whole initial configuration is an exact equilibrium.

The paper does not print the shape of the rod next to the clamp; this is the simplest choice
that has a vertical clamped end and a uniform helix (see docs/model.md, "Clamp geometry").
The other leads: a radius ramp onto the axis (:func:`ramp_helix_positions`) and the same
helix centred on the axis behind a held arm (:func:`connector_helix_positions`).

Consecutive helix beads are spaced by an exact chord ``b = L / (N - 1)``, so the discrete
contour length is exactly ``L``.
"""

from __future__ import annotations

import math

import numba
import numpy as np


def _chord_angle(R: float, p: float, b: float) -> float:
    """Helix parameter step ``dphi`` with chord ``b``: 2 R^2 (1 - cos dphi) + p^2 dphi^2 = b^2."""
    x = b / math.hypot(R, p)
    for _ in range(50):
        g = 2 * R * R * (1 - math.cos(x)) + p * p * x * x - b * b
        dg = 2 * R * R * math.sin(x) + 2 * p * p * x
        step = g / dg
        x -= step
        if abs(step) < 1e-15 * max(x, 1e-300):
            break
    return x


def helix_positions(length, helix_radius, pitch, n_beads, handedness="left"):
    """Bead positions of the hanging helix [same length unit as the inputs], shape (N, 3).

    Parameters
    ----------
    length, helix_radius, pitch : float
        ``L``, ``R``, ``P``.
    n_beads : int
        ``N``.
    handedness : {"left", "right"}

    Notes
    -----
    With ``p = P / 2 pi`` the helix is ``(R - R cos phi, -h R sin phi, -b - p phi)`` with
    ``h = +1`` for left- and ``-1`` for right-handed (a left-handed helix has negative torsion).
    """
    N = int(n_beads)
    b = length / (N - 1)
    R = helix_radius
    p = pitch / (2 * math.pi)
    h = 1.0 if handedness == "left" else -1.0
    dphi = _chord_angle(R, p, b)
    x = np.zeros((N, 3))
    x[1] = (0.0, 0.0, -b)
    phi = dphi * np.arange(N - 1)
    x[1:, 0] = R - R * np.cos(phi)
    x[1:, 1] = -h * R * np.sin(phi)
    x[1:, 2] = -b - p * phi
    return x


def ramp_helix_positions(length, helix_radius, pitch, n_beads, handedness="left", lead_turns=0.5):
    """Bead positions of a helix centred on the body axis with a radius ramp at the clamp.

    Bead 0 at the origin, bead 1 at ``(0, 0, -b)`` (vertical clamped bond); then the curve
    ``(r cos phi, h r sin phi, -b - p phi)`` with ``r = R (1 - cos(pi phi/phi_r))/2`` for
    ``phi < phi_r = 2 pi lead_turns`` and ``r = R`` beyond (tangent continuous, vertical at the
    clamp). Beads are marched along the curve at exact chord ``b`` (secant root finding), so the
    discrete contour length is exactly ``L``. ``h = +1`` gives a left-handed helix (negative
    torsion; descending, it turns counter-clockwise seen from above), ``h = -1`` a right-handed one.
    """
    N = int(n_beads)
    b = length / (N - 1)
    R = helix_radius
    p = pitch / (2 * math.pi)
    h = 1.0 if handedness == "left" else -1.0
    phi_r = 2 * math.pi * lead_turns

    def curve(phi):
        r = R * 0.5 * (1 - math.cos(math.pi * phi / phi_r)) if phi < phi_r else R
        return np.array([r * math.cos(phi), h * r * math.sin(phi), -b - p * phi])

    x = np.zeros((N, 3))
    x[1] = (0.0, 0.0, -b)
    phi = 0.0
    dphi0 = b / math.hypot(R, p)
    for k in range(2, N):
        prev = x[k - 1]
        # bracket the parameter where the chord from the previous bead reaches b
        lo, hi = phi, phi + min(dphi0, b / p if p > 0 else dphi0)
        while np.linalg.norm(curve(hi) - prev) < b:
            lo, hi = hi, hi + dphi0
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if np.linalg.norm(curve(mid) - prev) < b:
                lo = mid
            else:
                hi = mid
            if hi - lo < 1e-15 * max(1.0, hi):
                break
        phi = 0.5 * (lo + hi)
        x[k] = curve(phi)
    return x


def connector_arm_bonds(helix_radius: float, bond: float) -> int:
    """Bonds of the connector's radial arm (:func:`connector_helix_positions`): the fewest
    whose length ``R / k`` does not exceed the filament's bond ``b``."""
    return max(1, int(math.ceil(helix_radius / bond - 1e-9)))


def connector_helix_positions(length, helix_radius, pitch, n_beads, handedness="left"):
    """The helix of :func:`helix_positions` centred on the body axis and reached by a rigid arm.

    Bead 0 at the anchor (the origin); ``k`` beads along a radial arm in the anchor plane to
    ``(-R, 0, 0)`` (:func:`connector_arm_bonds`); then the ``n_beads - 1`` beads of
    :func:`helix_positions` from its bead 1 on, moved by ``-R`` along x, so that the first of
    them is ``(-R, 0, -b)`` below the arm's end (an axial bond of length ``b``) and the helix's
    axis is the body axis. ``n_beads + k`` beads; the arm and the axial bond are the joint's
    (held by the motor, no drag, no elastic energy); the filament proper is the kink lead's.
    """
    x = helix_positions(length, helix_radius, pitch, n_beads, handedness)
    b = length / (int(n_beads) - 1)
    k = connector_arm_bonds(helix_radius, b)
    arm = np.zeros((k, 3))
    arm[:, 0] = -helix_radius * np.arange(1, k + 1) / k
    hel = x[1:].copy()
    hel[:, 0] -= helix_radius
    return np.concatenate([x[:1], arm, hel])


def held_beads(fil, clamp=None) -> int:
    """Beads the motor holds at the start of the filament's chain (not in the hydrodynamics):
    2 (the clamped bond), plus the connector's arm for ``clamp.lead = "connector"``."""
    if clamp is not None and clamp.lead == "connector" and getattr(fil, "shape", "helix") != "straight":
        return 2 + connector_arm_bonds(fil.helix_radius, fil.bond_length)
    return 2


def straight_positions(length, n_beads) -> np.ndarray:
    """A straight rod of ``n_beads`` beads from the origin down the body axis (-z) [length unit
    of ``length``], bonds exactly ``length / (n_beads - 1)``."""
    x = np.zeros((int(n_beads), 3))
    x[:, 2] = -length * np.arange(int(n_beads)) / (int(n_beads) - 1)
    return x


def filament_positions(fil, clamp=None) -> np.ndarray:
    """Initial positions [m] of a :class:`flagwrap.params.Filament` with a clamp lead
    (``fil.shape = "straight"``: a straight rod, the lead does not apply). The connector lead
    adds its arm's beads (:func:`held_beads`)."""
    if getattr(fil, "shape", "helix") == "straight":
        return straight_positions(fil.length, fil.n_beads)
    if clamp is not None and clamp.lead == "connector":
        return connector_helix_positions(fil.length, fil.helix_radius, fil.pitch, fil.n_beads,
                                         fil.handedness)
    if clamp is not None and clamp.lead == "ramp":
        lt = clamp.lead_turns
        return ramp_helix_positions(fil.length, fil.helix_radius, fil.pitch, fil.n_beads,
                                    fil.handedness, lt)
    return helix_positions(fil.length, fil.helix_radius, fil.pitch, fil.n_beads, fil.handedness)


def min_nonlocal_distance(fil, clamp=None) -> float:
    """Smallest distance [m] between beads that are not contour neighbours within ``2a``.

    Beads closer than ``2a`` along the contour may overlap by construction (fine
    discretisations); any other pair closer than ``2a`` is a self-overlapping initial shape.
    """
    x = filament_positions(fil, clamp)
    N = len(x)
    b = fil.bond_length
    skip = int(math.ceil(2 * fil.cross_section_radius / b)) + 1
    if N > 4000:  # subsample rows to keep validation O(N) memory; exact enough for a guard
        idx = np.linspace(0, N - 1, 4000).astype(int)
    else:
        idx = np.arange(N)
    return float(_min_distance_beyond(np.ascontiguousarray(x), idx.astype(np.int64), skip))


@numba.njit(cache=True)
def _min_distance_beyond(x, rows, skip):
    """min |x_j - x_i| over i in ``rows`` and j > i + skip (no temporaries: at N = 2e5 the
    numpy version allocated ~20 GB over its 4000 rows and took 12 s)."""
    best2 = np.inf
    n = x.shape[0]
    for i in rows:
        for j in range(i + skip + 1, n):
            dx = x[j, 0] - x[i, 0]
            dy = x[j, 1] - x[i, 1]
            dz = x[j, 2] - x[i, 2]
            d2 = dx * dx + dy * dy + dz * dz
            if d2 < best2:
                best2 = d2
    return np.sqrt(best2)
