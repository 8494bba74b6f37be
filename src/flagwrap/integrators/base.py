"""Integrator interface.

An integrator advances ``dy/dt = Mob(y) G(y) + omega e_phi`` of a
:class:`flagwrap.system.rod_system.RodSystem` by one step ``h`` at constant motor speed ``omega``. It is a
pure function of (system, y, base, info, h, omega): the time loop (:mod:`flagwrap.simulation`)
owns time, output and the phase switches of the motor.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class StepResult:
    accepted: bool
    y: np.ndarray | None  # new state (None if rejected)
    info: object | None  # ForceInfo at the new state (its frames are the next base)
    h_next: float  # suggested next step
    error: float  # scaled error estimate (<= 1 accepted); nan for fixed-step schemes
    reason: str = ""


class Integrator:
    """Interface; ``order`` is the classical order, ``adaptive`` whether ``h`` is controlled."""

    order: int = 1
    adaptive: bool = False
    name: str = "base"

    def step(self, system, y, base, info, h, omega) -> StepResult:  # pragma: no cover
        raise NotImplementedError


class AdaptiveMixin:
    """Error-controlled stepping: a tolerance, a step-size controller
    (:class:`~flagwrap.integrators.controller.IController`, built from ``safety``, ``grow``,
    ``shrink`` unless one is given) and the end of a step (:meth:`conclude`)."""

    default_tol: float = 1e-4
    default_filter: bool = False

    def __init__(self, tol: float | None = None, safety: float = 0.9, grow: float = 4.0,
                 shrink: float = 0.2, filter_error: bool | None = None,
                 linear_solver: str = "auto", controller=None):
        from flagwrap.integrators.controller import IController

        self.tol = self.default_tol if tol is None else tol
        self.controller = controller or IController(safety, grow, shrink)
        self.filter_error = self.default_filter if filter_error is None else filter_error
        self.linear_solver = linear_solver

    def reject(self, h, reason) -> StepResult:
        return StepResult(False, None, None, self.controller.after_failure(h), np.inf, reason)

    def conclude(self, system, base, y_new, err, h, estimate_order) -> StepResult:
        if not np.isfinite(err) or not np.all(np.isfinite(y_new)):
            return self.reject(h, "non-finite state")
        h_next = self.controller.propose(h, err, estimate_order)
        if not self.controller.accept(err):
            return StepResult(False, None, None, h_next, err, "error above tolerance")
        try:
            info = system.forces(y_new, base)
        except ZeroDivisionError:  # numba raises where numpy would give inf: a bond of zero length
            return self.reject(h, "degenerate state (a bond of zero length)")
        return StepResult(True, y_new, info, h_next, err)


def scaled_error(system, err: np.ndarray, tol: float) -> float:
    """Max-norm of the local error: positions against ``tol`` [L], twist angles against
    ``10 tol`` (:meth:`flagwrap.system.layout.DofLayout.scaled_error`)."""
    return system.layout.scaled_error(err, tol)


def error_weights(system, tol: float) -> np.ndarray:
    """The absolute error each unknown is held to by :func:`scaled_error` (``inf`` for the
    prescribed motor angle): positions ``tol``, twist angles ``10 tol``."""
    return system.layout.error_weights(tol)
