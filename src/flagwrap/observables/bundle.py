"""Is a tuft of flagella a bundle? Separation and phase of several filaments (issue 28).

A bundle's helices turn about one common axis; flagella that have not bundled turn about
axes of their own. Over a whole number of helical turns the centroid of a helix lies on its
axis, so the centroids of the filaments' distal parts (arclength ``s >= distal L``, away from
the anchors, which sit apart on the body; :func:`last_turn` makes it the last whole helical
turn) measure how far apart their axes are:

    separation(t) = mean over pairs k < l of |c_k(t) - c_l(t)| / R,

``R`` the helix radius. Helices sharing an axis give ~0 (exactly 0 for whole turns of ideal
helices); helices side by side give >= 2 (their surfaces of revolution do not overlap).
``bundled`` is ``separation < 1`` (axes within one helix radius: their helices interleave).
The **phase** of filament ``k`` is the angle of its free end about the bundle axis (from the
mean centroid of the proximal parts to that of the distal parts, both on the helix axes), and the **phase lag** of ``k`` is its phase minus
filament 0's, wrapped to (-pi, pi]: a locked bundle keeps it constant.
"""

from __future__ import annotations

import math

import numpy as np

from flagwrap.observables._util import positions_array, positive


def last_turn(helix_radius: float, pitch: float, length: float) -> float:
    """The ``distal`` fraction that makes a filament's distal part its last whole helical
    turn: ``max(0, 1 - c / L)`` for rest radius ``R``, pitch ``P`` and length ``L``, with
    ``c = sqrt((2 pi R)^2 + P^2)`` the contour of one turn (the whole filament when it has
    less than one turn)."""
    per_turn = math.hypot(2.0 * math.pi * helix_radius, pitch)
    return max(0.0, 1.0 - per_turn / length)


def _centroids(x, slices, distal, proximal: bool = False):
    """Centroids of each filament's distal part (or, ``proximal``, the rest), (T, n, 3)."""
    out = []
    for sl in slices:
        xs = x[:, sl]
        k = int(np.floor(distal * (xs.shape[1] - 1)))
        out.append((xs[:, :k] if proximal else xs[:, k:]).mean(axis=1))
    return np.stack(out, axis=1)


def bundle_separation(positions, slices, helix_radius, distal: float = 0.5) -> np.ndarray:
    """``separation(t)`` (module docstring), (T,); ``slices``: each filament's beads."""
    x = positions_array(positions)
    x = x[None] if x.ndim == 2 else x
    R = positive("helix_radius", helix_radius)
    if len(slices) < 2:
        raise ValueError("bundle_separation needs at least two filaments")
    c = _centroids(x, slices, distal)
    k, m = np.triu_indices(len(slices), 1)
    return np.linalg.norm(c[:, k] - c[:, m], axis=2).mean(axis=1) / R


def bundle_phases(positions, slices, distal: float = 0.5) -> np.ndarray:
    """Each filament's phase about the bundle axis [rad], (T, n) (module docstring)."""
    x = positions_array(positions)
    x = x[None] if x.ndim == 2 else x
    c = _centroids(x, slices, distal).mean(axis=1)  # (T, 3)
    base = _centroids(x, slices, distal, proximal=True).mean(axis=1)
    axis = c - base
    axis /= np.linalg.norm(axis, axis=1)[:, None]
    # a fixed reference direction perpendicular to the axis, per frame
    ref = np.where(np.abs(axis[:, :1]) < 0.9, np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
    e1 = ref - (ref * axis).sum(axis=1)[:, None] * axis
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    e2 = np.cross(axis, e1)
    tips = np.stack([x[:, sl.stop - 1] for sl in slices], axis=1) - c[:, None]
    return np.arctan2((tips * e2[:, None]).sum(axis=2), (tips * e1[:, None]).sum(axis=2))


def phase_lags(phases) -> np.ndarray:
    """Phase of each filament minus filament 0's, wrapped to (-pi, pi], (T, n)."""
    p = np.asarray(phases, float)
    return np.angle(np.exp(1j * (p - p[:, :1])))


def bundle_summary(turns, positions, slices, helix_radius, final_turns: float = 1.0,
                   distal: float = 0.5, bundled_below: float = 1.0) -> dict:
    """Means over the final ``final_turns`` motor turns: ``separation``, ``bundled``
    (``separation < bundled_below``), the phase lags' means and spreads (circular) [rad]."""
    turns = np.asarray(turns, float)
    sep = bundle_separation(positions, slices, helix_radius, distal)
    lag = phase_lags(bundle_phases(positions, slices, distal))
    w = turns >= turns[-1] - final_turns
    z = np.exp(1j * lag[w])
    mean = np.angle(z.mean(axis=0))
    spread = np.sqrt(np.maximum(0.0, -2.0 * np.log(np.abs(z.mean(axis=0)))))
    return {"separation": float(sep[w].mean()), "bundled": bool(sep[w].mean() < bundled_below),
            "phase_lag": [float(v) for v in mean[1:]],
            "phase_lag_spread": [float(v) for v in spread[1:]],
            "separation_series": sep, "phase_lag_series": lag}
