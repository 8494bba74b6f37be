"""ROS2: a two-stage, L-stable, linearly implicit Rosenbrock (W-) method with error control.

Verwer, Spee, Blom & Hundsdorfer, SIAM J. Sci. Comput. 20, 1456 (1999), with
``gamma = 1 + 1/sqrt(2)`` and ``W = I - gamma h Mob J_G``::

    W k1 = f(y_n)
    W k2 = f(y_n + h k1) - 2 k1
    y_{n+1} = y_n + 3/2 h k1 + 1/2 h k2            (order 2 for any W)
    err     = y_{n+1} - (y_n + h k1) = h (k1 + k2)/2 (embedded linearly implicit Euler)

``J_G`` is the Jacobian of the elastic + contact forces (coloured finite differences) and
``Mob`` the mobility at ``y_n``; freezing the mobility in ``W`` keeps order 2 because ROS2 is
a W-method. All stiff elastic modes (stretching, twist, bending) are damped implicitly, so the
step is set by accuracy (``tol``), not by the stiffest spring.
"""

from __future__ import annotations

import math

import numpy as np

from flagwrap.integrators.base import (AdaptiveMixin, Integrator, StepResult, error_weights,
                                      scaled_error)
from flagwrap.integrators.linear import SingularW, make_w

GAMMA = 1.0 + 1.0 / math.sqrt(2.0)


class ROS2(AdaptiveMixin, Integrator):
    order = 2
    adaptive = True
    name = "rosenbrock"

    default_tol = 1e-3
    default_filter = True  # see the error-estimate comment in step()

    def step(self, system, y, base, info, h, omega) -> StepResult:
        G0 = info.G
        f0 = system.apply_mobility(y, G0)
        f0[system.i_phi] = omega
        try:
            # the stages k_i are rates: y moves by ~h k_i, so an iterative solve needs them to
            # kappa x tol / h
            W = make_w(self.linear_solver, system, y, base, G0, GAMMA * h,
                       err_scale=error_weights(system, self.tol) / h)
            k1 = W.solve(f0)
        except SingularW as exc:
            return self.reject(h, f"singular W ({exc})")
        y1 = y + h * k1
        if not np.all(np.isfinite(y1)):
            return self.reject(h, "non-finite stage")
        try:
            f1, _ = system.rhs(y1, base, omega)
        except ZeroDivisionError:  # a stage so far off that a bond has zero length
            return self.reject(h, "degenerate stage (a bond of zero length)")
        try:
            k2 = W.solve(f1 - 2.0 * k1)
        except SingularW as exc:
            return self.reject(h, str(exc))
        y_new = y + h * (1.5 * k1 + 0.5 * k2)
        # Shampine's filter: W^-1 applied to the raw estimate removes the spurious error of
        # the stiff (instantly relaxing) components, which would otherwise cap the step.
        err_vec = 0.5 * h * (k1 + k2)
        if self.filter_error:
            err_vec = W.solve(err_vec)
        err = scaled_error(system, err_vec, self.tol)
        return self.conclude(system, base, y_new, err, h, estimate_order=1)
