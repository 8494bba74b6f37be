"""Explicit (forward) Euler: the paper-style reference stepper.

``y_{n+1} = y_n + h f(y_n)``; first order; stable only for ``h`` below the fastest elastic
relaxation time (stretching springs: ``h < ~2 M / (k_s mu_hat)``), so it is slow for the paper's
stiff bead-spring model. Kept as the reference that faster schemes are checked against.
"""

from __future__ import annotations

import numpy as np

from flagwrap.integrators.base import Integrator, StepResult


class ExplicitEuler(Integrator):
    order = 1
    adaptive = False
    name = "euler"

    def step(self, system, y, base, info, h, omega) -> StepResult:
        f = system.velocity(y, info, omega)
        y_new = y + h * f
        if not np.all(np.isfinite(y_new)):
            return StepResult(False, None, None, h, np.nan, "non-finite state")
        try:
            info_new = system.forces(y_new, base)
        except ZeroDivisionError:  # numba raises where numpy would give inf: a bond of zero length
            return StepResult(False, None, None, h, np.nan, "degenerate state (a bond of zero length)")
        return StepResult(True, y_new, info_new, h, np.nan)
