"""One Rosenbrock W-method step driven by a tableau (:mod:`flagwrap.integrators.tableau`).

``W = I - gamma h Mob(y_n) J_G``: ``J_G`` the Jacobian of the generalized forces (exact
stretching Hessian + coloured finite differences + the interactions' Hessians) and the
mobility frozen at ``y_n``. The schemes are W-methods, so they keep their order for this
approximate Jacobian (Rang & Angermann 2005; Verwer et al. 1999); all stiff elastic modes are
damped implicitly, so the step is set by accuracy (``tol``), not by the stiffest spring.
:class:`ROS34PW2` (default) and :class:`ROS2` are this stepper with their tableaus.
"""

from __future__ import annotations

import numpy as np

from flagwrap.integrators import tableau as T
from flagwrap.integrators.base import (AdaptiveMixin, Integrator, StepResult, error_weights,
                                      scaled_error)
from flagwrap.integrators.linear import SingularW, make_w


class RosenbrockW(AdaptiveMixin, Integrator):
    """A Rosenbrock W-method step for the tableau ``self.tableau`` (class attribute, or
    ``RosenbrockW(tableau=...)``)."""

    adaptive = True
    tableau: T.RosenbrockTableau = T.ROS34PW2

    def __init__(self, tol=None, *, tableau: T.RosenbrockTableau | None = None, **kw):
        if tableau is not None:
            self.tableau = tableau
        super().__init__(tol, **kw)

    # what the scheme is comes from its tableau
    order = property(lambda self: self.tableau.order)
    name = property(lambda self: self.tableau.name)
    default_tol = property(lambda self: self.tableau.default_tol)
    default_filter = property(lambda self: self.tableau.filter_error)

    def step(self, system, y, base, info, h, omega) -> StepResult:
        tb = self.tableau
        gh = tb.gamma * h
        try:
            # stage increments u_i enter y_new and the error estimate with O(1) weights, so
            # an iterative solve needs each to kappa x the step tolerance
            W = make_w(self.linear_solver, system, y, base, info.G, gh,
                       err_scale=error_weights(system, self.tol), omega=omega)
        except SingularW as exc:
            return self.reject(h, f"singular W ({exc})")
        a, c = tb.a, tb.c
        split = getattr(system, "stage_split", None)
        U = np.empty((tb.stages, system.ny))
        for i in range(tb.stages):
            if i == 0:
                f = system.velocity(y, info, omega)
            else:
                Yi = y + _combine(a[i, :i], U[:i], split)
                if not np.all(np.isfinite(Yi)):
                    return self.reject(h, "non-finite stage")
                try:
                    f, _ = system.rhs(Yi, base, omega)
                except ZeroDivisionError:  # a stage so far off that a bond has zero length
                    return self.reject(h, "degenerate stage (a bond of zero length)")
                except np.linalg.LinAlgError:  # e.g. a free body's stage pose through a wall
                    return self.reject(h, "degenerate stage (a blob matrix not positive "
                                          "definite)")
            rhs = f + _combine(c[i, :i], U[:i], split) / h if i else f
            try:
                U[i] = W.solve(gh * rhs)
            except SingularW as exc:
                return self.reject(h, str(exc))
        y_new = y + _combine(tb.m, U, split)
        err_vec = _combine(tb.e, U, split)
        if self.filter_error:
            err_vec = W.solve(err_vec)
        err = scaled_error(system, err_vec, self.tol)
        return self.conclude(system, base, y_new, err, h, estimate_order=tb.estimate_order)


def _combine(coef, U, split):
    """``coef @ U``; with ``split`` (a system's ``stage_split``) the first ``split`` columns
    and the rest as two products, so that the first ``split`` unknowns are combined exactly
    as a system of only those would combine them (BLAS treats a vector's tail apart from its
    body, so the same columns in a longer product may round differently). Systems without
    ``stage_split`` take the one product, as always."""
    if split is None:
        return coef @ U
    out = np.empty(U.shape[1])
    out[:split] = coef @ U[:, :split]
    out[split:] = coef @ U[:, split:]
    return out


class ROS34PW2(RosenbrockW):
    """4 stages, order 3, L-stable, embedded order 2 (:data:`tableau.ROS34PW2`); the default."""

    tableau = T.ROS34PW2


class ROS2(RosenbrockW):
    """2 stages, order 2, L-stable, embedded order 1, Shampine's error filter
    (:data:`tableau.ROS2`)."""

    tableau = T.ROS2
