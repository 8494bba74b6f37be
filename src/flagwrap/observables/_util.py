"""Shared argument checks of the observables (private)."""

from __future__ import annotations

import math

import numpy as np

from flagwrap.errors import UserInputError


def positions_array(positions, min_beads: int = 2) -> np.ndarray:
    """``positions`` as a float array of shape ``(..., N, 3)`` with ``N >= min_beads``."""
    x = np.asarray(positions, dtype=float)
    if x.ndim < 2 or x.shape[-1] != 3 or x.shape[-2] < min_beads:
        raise UserInputError(
            f"positions must have shape (..., N, 3) with N >= {min_beads}, got {x.shape}"
        )
    return x


def positive(name: str, value) -> float:
    v = float(value)
    if not (math.isfinite(v) and v > 0.0):
        raise UserInputError(f"{name} must be a finite number > 0, got {value!r}")
    return v
