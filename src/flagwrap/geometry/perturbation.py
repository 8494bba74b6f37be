"""Seed perturbations of the initial state (:class:`flagwrap.params.Initial`)."""

from __future__ import annotations

import numpy as np


def displacement(n_beads: int, amplitude: float, mode: str = "random", seed: int = 0) -> np.ndarray:
    """Bead displacements (N, 3) whose largest norm is ``amplitude``, growing as ``(s/L)^2``
    from the clamped end (so beads 0 and 1 move by O(b^2), and by exactly 0 after
    :meth:`~flagwrap.system.rod_system.RodSystem.initial_y` keeps the clamp's beads).

    ``"random"``: in each direction the sum of ``sin(k pi s / L)`` for k = 1..4 with standard
    normal amplitudes from ``numpy.random.default_rng(seed)`` plus a constant; ``"lateral"``:
    along x only. Deterministic for a given seed.
    """
    s = np.linspace(0.0, 1.0, n_beads)
    ramp = s**2
    if mode == "lateral":
        d = np.zeros((n_beads, 3))
        d[:, 0] = ramp
    else:
        rng = np.random.default_rng(seed)
        c = rng.standard_normal((5, 3))
        basis = np.column_stack([np.ones_like(s)] + [np.sin(k * np.pi * s) for k in range(1, 5)])
        d = ramp[:, None] * (basis @ c)
    peak = np.linalg.norm(d, axis=1).max()
    return d * (amplitude / peak) if peak > 0 else d
