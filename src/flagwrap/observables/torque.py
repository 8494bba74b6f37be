"""Motor torque, rescaled as in the paper: ``N_m R / A`` (paper Fig. 4(c)).

The paper reports ``N_m R / A ~ 0.5`` for a stably twirling helix (``omega/omega_c = 0.85``), a
peak ``~ 1`` at the first complete CW turn for ``omega/omega_c = 2.05`` and a plateau
``~ 0.5`` once the helix has wrapped; the onset torque is ``N_c ~ 0.5 A/R`` (main text,
"Torque-induced buckling and wrapping"; :mod:`flagwrap.theory.scaling`). Signs follow the run
file: CCW positive, so the CW phase has negative torque.
"""

from __future__ import annotations

import numpy as np

from flagwrap.errors import UserInputError
from flagwrap.observables._util import positive


def reduced_torque(torque, helix_radius, bending_modulus) -> np.ndarray:
    """``N_m R / A`` (dimensionless).

    Parameters
    ----------
    torque : array_like
        motor torque ``N_m`` [force*length].
    helix_radius : float
        ``R`` [length].
    bending_modulus : float
        ``A`` [force*length^2], same units.
    """
    return np.asarray(torque, dtype=float) * positive("helix_radius", helix_radius) / positive(
        "bending_modulus", bending_modulus)


def _window(turns, values, start, stop):
    t = np.asarray(turns, dtype=float)
    v = np.asarray(values, dtype=float)
    if t.shape != v.shape or t.ndim != 1:
        raise UserInputError(f"turns and values must be 1-D of equal length, got {t.shape}, {v.shape}")
    sel = (t >= start) & (t <= stop)
    return t[sel], v[sel]


def torque_peak(turns, torque, start=-np.inf, stop=np.inf) -> tuple[float, float]:
    """Largest ``|torque|`` in ``start <= t/T <= stop`` and when it happens.

    Parameters
    ----------
    turns : array_like, shape (T,)
        ``t/T``.
    torque : array_like, shape (T,)
        torque, any unit (typically ``N_m R / A``).
    start, stop : float
        window in ``t/T``.

    Returns
    -------
    (value, turns) : tuple of float
        the signed torque at its largest magnitude, and its ``t/T``; ``(nan, nan)`` if the
        window is empty.
    """
    t, v = _window(turns, torque, start, stop)
    if t.size == 0:
        return float("nan"), float("nan")
    i = int(np.argmax(np.abs(v)))
    return float(v[i]), float(t[i])


def cw_torque_peak(turns, torque, switch_turns: float) -> tuple[float, float]:
    """The CW torque peak: the most negative torque strictly after the CCW -> CW switch
    (the frame at ``switch_turns`` still belongs to the CCW phase), and its ``t/T`` after
    the switch; ``(nan, nan)`` without CW frames. Paper Fig. 4(c): the peak ``N_m``."""
    t = np.asarray(turns, dtype=float)
    v = np.asarray(torque, dtype=float)
    cw = np.flatnonzero(t > switch_turns)
    if not cw.size:
        return float("nan"), float("nan")
    j = int(cw[np.argmin(v[cw])])
    return float(v[j]), float(t[j] - switch_turns)


def plateau_value(turns, values, last_turns=1.0) -> float:
    """Median of ``values`` over the last ``last_turns`` turns (a stationary value).

    The median over one motor turn removes the once-per-turn whirling oscillation and is
    insensitive to isolated spikes; ``nan`` if there are no samples.
    """
    t = np.asarray(turns, dtype=float)
    if t.size == 0:
        return float("nan")
    _, v = _window(t, values, t[-1] - positive("last_turns", last_turns), t[-1])
    return float(np.median(v)) if v.size else float("nan")
