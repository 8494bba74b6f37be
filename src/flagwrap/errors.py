"""Exceptions with a user-facing meaning, and the one check of a number's range that raises
them (every module that validates a number calls :func:`check_finite` or
:func:`check_positive`)."""

import math


class UserInputError(ValueError):
    """A parameter, config file or input file the user can fix; the CLI exits with code 2."""


class SimulationError(RuntimeError):
    """A run that cannot continue (NaN, overlap, step size underflow); partial output is kept."""


class ResultError(SimulationError):
    """A computed answer came out non-finite or outside the physical range of its quantity
    (a fit to inconsistent data, a degenerate calibration): it is not printed as an answer;
    the CLI prints the one-line reason and exits with code 1 (the inputs passed their checks)."""


class OutputWriteError(UserInputError):
    """A finished result could not be written where asked (disk full, folder gone); the
    message names where it was kept instead. Exit code 1 (the input was fine)."""


def check_finite(name: str, value) -> float:
    """``value`` as a float, or a one-line :class:`UserInputError` naming ``name``: not a
    number (a bool is not one), or not finite."""
    import numpy as np

    if isinstance(value, (bool, np.bool_)):
        raise UserInputError(f"{name} must be a number, got {value!r}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise UserInputError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(v):
        raise UserInputError(f"{name} must be finite, got {value!r}")
    return v


def check_positive(name: str, value, unit: str = "", allow_zero: bool = False) -> float:
    """:func:`check_finite`, then ``> 0`` (``>= 0`` with ``allow_zero``); ``unit`` is named in
    the message."""
    v = check_finite(name, value)
    if v < 0 or (v == 0 and not allow_zero):
        raise UserInputError(f"{name} must be {'>=' if allow_zero else '>'} 0"
                             f"{(' ' + unit) if unit else ''}, got {value!r}")
    return v


def check_range(name: str, value, lo: float, hi: float, unit: str = "") -> float:
    """:func:`check_finite`, then ``lo <= value <= hi``; the message names ``name``, the range
    and ``unit`` (the physical range of a quantity, so that nothing downstream overflows)."""
    v = check_finite(name, value)
    if not lo <= v <= hi:
        raise UserInputError(f"{name} must be in [{lo:g}, {hi:g}]{(' ' + unit) if unit else ''}, got {value!r}")
    return v


def check_result(name: str, value, lo: float, hi: float, unit: str = "", hint: str = "") -> float:
    """A computed ``value`` that must be finite and within ``[lo, hi]``, else a one-line
    :class:`ResultError` naming it, the range and ``hint`` (what to check)."""
    v = float(value)
    if not (math.isfinite(v) and lo <= v <= hi):
        u = (" " + unit) if unit else ""
        raise ResultError(f"the result {name} = {v:.6g}{u} is not finite or outside [{lo:g}, {hi:g}]{u}"
                          f"{': ' + hint if hint else ''}")
    return v
