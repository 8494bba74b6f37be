"""Shared argument checks of the observables (private)."""

from __future__ import annotations

import numpy as np

from flagwrap.errors import UserInputError, check_positive


def positions_array(positions, min_beads: int = 2) -> np.ndarray:
    """``positions`` as a float array of shape ``(..., N, 3)`` with ``N >= min_beads``."""
    x = np.asarray(positions, dtype=float)
    if x.ndim < 2 or x.shape[-1] != 3 or x.shape[-2] < min_beads:
        raise UserInputError(
            f"positions must have shape (..., N, 3) with N >= {min_beads}, got {x.shape}"
        )
    return x


def positive(name: str, value) -> float:
    """``value`` checked finite and > 0 (:func:`flagwrap.errors.check_positive`)."""
    return check_positive(name, value)
