"""Winding of the filament about the body axis (+z).

A wrapped filament is coiled around the cell body (paper, main text, Fig. 4(a), SI Movie 3);
a folded one is buckled but does not encircle the body (SI Movie 4). The winding angle
measures how far the filament turns about the body axis along its contour:

    W = sum_j  wrap(phi_{j+1} - phi_j),   phi_j = atan2(y_j, x_j),

with ``wrap`` mapping to ``(-pi, pi]`` (the unwrapped azimuth along the contour). Each term
is exact if the bond subtends less than half a turn about the axis, which holds for beads at
a distance from the axis well above the bond length; near the axis (e.g. the hanging helix,
whose own axis is offset by ``R`` from the body axis so that it passes close to it) the
azimuth jumps and the sum is not meaningful. Hence the ``mask``: count only bonds whose two
beads are both selected, typically those beside the body (:mod:`.contact`).
"""

from __future__ import annotations

import numpy as np

from flagwrap.errors import UserInputError
from flagwrap.observables._util import positions_array


def azimuth(positions) -> np.ndarray:
    """Azimuth ``atan2(y, x)`` of each bead about the body axis [rad], shape ``(..., N)``."""
    x = positions_array(positions, min_beads=1)
    return np.arctan2(x[..., 1], x[..., 0])


def _increments(positions, mask):
    phi = azimuth(positions)
    d = np.diff(phi, axis=-1)
    d = (d + np.pi) % (2 * np.pi) - np.pi
    if mask is not None:
        m = np.asarray(mask, dtype=bool)
        if m.shape != phi.shape:
            raise UserInputError(f"mask shape {m.shape} does not match beads {phi.shape}")
        d = np.where(m[..., 1:] & m[..., :-1], d, 0.0)
    return d


def winding_angle(positions, mask=None) -> np.ndarray:
    """Cumulative winding angle along the contour, ``W_i = sum_{j<i} wrap(phi_{j+1}-phi_j)``.

    Parameters
    ----------
    positions : array_like, shape (..., N, 3)
        bead centres [length], body axis = z axis.
    mask : array_like of bool, shape (..., N), optional
        beads that count; a bond adds its increment only if both its beads are selected.

    Returns
    -------
    ndarray, shape (..., N)
        [rad], ``W_0 = 0``; positive = counterclockwise seen from +z (from above the body).
    """
    d = _increments(positions, mask)
    zero = np.zeros(d.shape[:-1] + (1,))
    return np.concatenate([zero, np.cumsum(d, axis=-1)], axis=-1)


def winding_turns(positions, mask=None) -> np.ndarray:
    """Total signed winding ``W / 2 pi`` [turns] about the body axis, shape ``(...)``.

    A filament wound ``k`` times around a cylinder coaxial with z gives ``+-k``.
    """
    return _increments(positions, mask).sum(axis=-1) / (2 * np.pi)
