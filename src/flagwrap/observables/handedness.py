"""Local handedness along the filament and the perversion between LH and RH parts.

The onset of buckling is "a kink connecting the LH and RH sections near the driving end, a
morphology known as perversion" (paper, main text, "Torque-induced buckling and wrapping";
McMillen & Goriely 2002). Locally the handedness of a space curve is the sign of its
torsion: positive for a right-handed (RH) helix, negative for a left-handed (LH) one.

Discrete torsion. With bond vectors ``e_j = r_{j+1} - r_j`` and binormals
``b_j = e_{j-1} x e_j``, the torsion angle at bond ``j`` is the signed angle from ``b_j`` to
``b_{j+1}`` about ``e_j``::

    phi_j = atan2((b_j x b_{j+1}) . e_j / |e_j|,  b_j . b_{j+1})

and ``b_j x b_{j+1} = [e_{j-1} . (e_j x e_{j+1})] e_j``, so ``sign(phi_j)`` is the sign of the
triple product of three consecutive bonds. ``phi_j / |e_j|`` converges to the torsion
``tau = c / (R^2 + c^2)`` (``c = P / 2 pi``) of a helix of radius ``R`` and pitch ``P``, to
second order in the bond length. Element ``k`` of the returned arrays (``k = 0..N-4``)
belongs to bond ``j = k + 1`` (beads ``k+1``, ``k+2``).
"""

from __future__ import annotations

import numpy as np

from flagwrap.errors import UserInputError
from flagwrap.observables._util import positions_array


def _bonds(positions):
    x = positions_array(positions, min_beads=4)
    return np.diff(x, axis=-2)


def discrete_torsion(positions) -> np.ndarray:
    """Discrete torsion ``phi_j / |e_j|`` at bonds ``1..N-3``.

    Parameters
    ----------
    positions : array_like, shape (..., N, 3)
        bead centres [length], ``N >= 4``.

    Returns
    -------
    ndarray, shape (..., N-3)
        torsion [1/length]; positive = right-handed. ``nan`` where a binormal vanishes
        (three collinear beads: torsion undefined).
    """
    e = _bonds(positions)
    b = np.cross(e[..., :-1, :], e[..., 1:, :])  # b_j, j = 1..N-2 -> (..., N-2, 3)
    b0, b1 = b[..., :-1, :], b[..., 1:, :]
    ej = e[..., 1:-1, :]
    ln = np.linalg.norm(ej, axis=-1)
    sin_part = np.einsum("...i,...i->...", np.cross(b0, b1), ej) / ln
    cos_part = np.einsum("...i,...i->...", b0, b1)
    with np.errstate(invalid="ignore", divide="ignore"):
        phi = np.arctan2(sin_part, cos_part)
        degenerate = (np.linalg.norm(b0, axis=-1) == 0) | (np.linalg.norm(b1, axis=-1) == 0)
        return np.where(degenerate, np.nan, phi / ln)


def local_handedness(positions, min_bend_angle: float = 1e-3) -> np.ndarray:
    """Sign of the discrete torsion: +1 right-handed, -1 left-handed, 0 undefined.

    Parameters
    ----------
    positions : array_like, shape (..., N, 3)
        bead centres [length].
    min_bend_angle : float
        [rad] where the turning angle between ``e_{j-1}`` and ``e_j`` or between ``e_j`` and
        ``e_{j+1}`` is below this, the curve is locally straight, its torsion is numerical
        noise, and the handedness is reported as 0.

    Returns
    -------
    ndarray of int8, shape (..., N-3)
    """
    if not min_bend_angle >= 0:
        raise UserInputError(f"min_bend_angle must be >= 0, got {min_bend_angle!r}")
    e = _bonds(positions)
    n = np.linalg.norm(e, axis=-1)
    u = e / np.where(n > 0, n, 1.0)[..., None]
    bend = np.arccos(np.clip(np.einsum("...i,...i->...", u[..., :-1, :], u[..., 1:, :]), -1, 1))
    straight = (bend[..., :-1] < min_bend_angle) | (bend[..., 1:] < min_bend_angle)
    tau = discrete_torsion(positions)
    s = np.sign(np.nan_to_num(tau, nan=0.0)).astype(np.int8)
    s[straight] = 0
    return s


def perversions(handedness, min_section: int = 3) -> list[int]:
    """Beads at which the handedness flips between homochiral sections, from the clamp out.

    Denoising: the nonzero elements of ``h`` (:func:`local_handedness`) are grouped into runs
    of equal sign (zeros are skipped); the shortest run shorter than ``min_section`` is merged
    into its neighbours, repeatedly, until every run has at least ``min_section`` elements
    (or one run is left). A single misread bond therefore neither creates nor moves a
    perversion, while a genuine RH section of ``min_section`` bonds or more is kept. The
    paper's buckled helix shows LH near the clamp, a kink, an RH section, and (here) usually a
    second kink back to LH further out.

    Parameters
    ----------
    handedness : array_like of int, shape (N-3,)
        local handedness of one frame; element ``k`` belongs to bond ``k + 1``.
    min_section : int
        minimum number of torsion elements of a homochiral section (>= 1).

    Returns
    -------
    list of int
        bead index of each kink: the bead shared by the last bond of one section and the
        first bond of the next (``k + 1`` for a section starting at element ``k``).
    """
    h = np.sign(np.asarray(handedness)).astype(int)
    if h.ndim != 1:
        raise UserInputError(f"handedness of one frame must be 1-D, got shape {h.shape}")
    min_section = int(min_section)
    if min_section < 1:
        raise UserInputError(f"min_section must be >= 1, got {min_section}")
    idx = np.flatnonzero(h)
    if idx.size == 0:
        return []
    # runs: [sign, first element index, count]
    runs = []
    for k in idx:
        if runs and runs[-1][0] == h[k]:
            runs[-1][2] += 1
        else:
            runs.append([int(h[k]), int(k), 1])
    while len(runs) > 1:
        i = min(range(len(runs)), key=lambda j: runs[j][2])
        if runs[i][2] >= min_section:
            break
        # drop run i; its neighbours (same sign as each other) merge
        left = runs[i - 1] if i > 0 else None
        right = runs[i + 1] if i + 1 < len(runs) else None
        if left is not None and right is not None:
            left[2] += right[2]
            del runs[i:i + 2]
        else:
            del runs[i]
    return [r[1] + 1 for r in runs[1:]]


def perversion_index(handedness, min_section: int = 3) -> np.ndarray:
    """Bead of the perversion nearest the clamp, per frame (-1: homochiral filament).

    Parameters
    ----------
    handedness : array_like of int, shape (..., N-3)
        local handedness (:func:`local_handedness`).
    min_section : int
        see :func:`perversions`.

    Returns
    -------
    ndarray of int, shape (...)
    """
    h = np.asarray(handedness)
    if h.ndim < 1:
        raise UserInputError("handedness must be at least 1-D")
    flat = h.reshape(-1, h.shape[-1])
    out = np.array([(p[0] if (p := perversions(row, min_section)) else -1) for row in flat], dtype=int)
    return out.reshape(h.shape[:-1])


def right_handed_fraction(handedness) -> np.ndarray:
    """Fraction of the defined (nonzero) torsion elements that are right-handed, ``(...)``."""
    h = np.asarray(handedness)
    nz = (h != 0).sum(axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(nz > 0, (h > 0).sum(axis=-1) / nz, np.nan)
