"""ROS34PW2: a 4-stage, 3rd-order, L-stable Rosenbrock W-method with embedded 2nd order.

Rang & Angermann, "New Rosenbrock W-methods of order 3 for partial differential algebraic
equations of index 1", BIT Numer. Math. 45, 761 (2005). As a W-method it keeps order 3 for any
approximation of the Jacobian in ``W`` (here: the mobility frozen at the start of the step,
``J ~ Mob(y_n) dG/dy``). Implemented in the transformed variables of Hairer & Wanner
(Solving ODEs II, Sec. IV.7) so no Jacobian-vector products are needed::

    W u_i = gamma h [ f(y + sum_j a_ij u_j) + sum_j (c_ij / h) u_j ],  W = I - gamma h J
    y_{n+1} = y + sum_i m_i u_i,  err = sum_i (m_i - mhat_i) u_i

with ``A = alpha Gamma^-1``, ``C = diag(1/gamma) - Gamma^-1``, ``m = b Gamma^-1`` computed here
from the published (alpha, gamma, b, bhat) tableau.
"""

from __future__ import annotations

import numpy as np

from flagwrap.integrators.base import (AdaptiveMixin, Integrator, StepResult, error_weights,
                                      scaled_error)
from flagwrap.integrators.linear import SingularW, make_w

GAMMA = 4.3586652150845900e-01
_ALPHA = np.array([
    [0.0, 0.0, 0.0, 0.0],
    [8.7173304301691801e-01, 0.0, 0.0, 0.0],
    [8.4457060015369423e-01, -1.1299064236484185e-01, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
])
_GAMMA = np.array([
    [GAMMA, 0.0, 0.0, 0.0],
    [-8.7173304301691801e-01, GAMMA, 0.0, 0.0],
    [-9.0338057013044082e-01, 5.4180672388095326e-02, GAMMA, 0.0],
    [2.4212380706095346e-01, -1.2232505839045147e+00, 5.4526025533510214e-01, GAMMA],
])
_B = np.array([2.4212380706095346e-01, -1.2232505839045147e+00, 1.5452602553351020e+00, GAMMA])
_BHAT = np.array([3.7810903145819369e-01, -9.6042292212423178e-02, 0.5, 2.1793326075422950e-01])

_GINV = np.linalg.inv(_GAMMA)
A_T = _ALPHA @ _GINV
C_T = np.diag(1.0 / np.diag(_GAMMA)) - _GINV
M_T = _B @ _GINV
E_T = (_B - _BHAT) @ _GINV


class ROS34PW2(AdaptiveMixin, Integrator):
    order = 3
    adaptive = True
    name = "ros34pw2"

    default_tol = 1e-4
    default_filter = False  # see the error-estimate comment in step()

    def step(self, system, y, base, info, h, omega) -> StepResult:
        try:
            # stage increments U_i enter y_new and the error estimate with O(1) weights, so
            # an iterative solve needs each to kappa x the step tolerance
            W = make_w(self.linear_solver, system, y, base, info.G, GAMMA * h,
                       err_scale=error_weights(system, self.tol))
        except SingularW as exc:
            return self.reject(h, f"singular W ({exc})")
        s = 4
        U = np.empty((s, system.ny))
        for i in range(s):
            if i == 0:
                f = system.apply_mobility(y, info.G)
                f[system.i_phi] = omega
            else:
                Yi = y + A_T[i, :i] @ U[:i]
                if not np.all(np.isfinite(Yi)):
                    return self.reject(h, "non-finite stage")
                try:
                    f, _ = system.rhs(Yi, base, omega)
                except ZeroDivisionError:  # a stage so far off that a bond has zero length
                    return self.reject(h, "degenerate stage (a bond of zero length)")
            rhs = f + (C_T[i, :i] @ U[:i]) / h if i else f
            try:
                U[i] = W.solve((GAMMA * h) * rhs)
            except SingularW as exc:
                return self.reject(h, str(exc))
        y_new = y + M_T @ U
        err_vec = E_T @ U
        if self.filter_error:
            err_vec = W.solve(err_vec)
        err = scaled_error(system, err_vec, self.tol)
        return self.conclude(system, base, y_new, err, h, estimate_order=2)
